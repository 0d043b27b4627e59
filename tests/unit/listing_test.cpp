// Programs written as the family's instruction list (docs/program-language.md): each mnemonic
// of WinProladder's mnemonic view (fbs, fb) and of the VB's FX-style list, the blocks and the
// branch stack, edges per scan, timers and counters, function instructions taking their enable
// from the rung, and the refusals, each at file:line:col naming the mnemonic.

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "plcemu/config/config.hpp"
#include "plcemu/daemon/plc.hpp"
#include "plcemu/engine/holds.hpp"
#include "plcemu/engine/loops.hpp"
#include "support/listing_plc.hpp"
#include "support/profiles.hpp"

namespace plcemu::instructions {
namespace {

using image::Area;
using testing::expect_listing_error;
using testing::ListingPlc;

// X0 … X3 as a truth table's inputs.
void inputs(ListingPlc& p, std::initializer_list<bool> xs) {
    std::uint32_t i = 0;
    for (const bool x : xs) p.set(Area::X, i++, x);
}

// ---- fbs / fb: WinProladder's mnemonic view ----

TEST(FatekListing, SealInRungLatchesAndDropsOut) {
    // Start X0, stop X1 (normally closed in the rung), Y0 holds itself.
    ListingPlc p("fbs", {"ORG X0", "OR Y0", "AND NOT X1", "OUT Y0"});
    p.scan();
    EXPECT_FALSE(p.y(0));
    inputs(p, {true, false});
    p.scan();
    EXPECT_TRUE(p.y(0));
    inputs(p, {false, false});
    p.scan();
    EXPECT_TRUE(p.y(0));  // sealed in
    inputs(p, {false, true});
    p.scan();
    EXPECT_FALSE(p.y(0));
    inputs(p, {false, false});
    p.scan();
    EXPECT_FALSE(p.y(0));
}

TEST(FatekListing, BlocksJoinWithAndldAndOrld) {
    // Y0 = (X0 OR X1) AND (X2 OR X3); Y1 = (X0 AND X1) OR (X2 AND X3).
    ListingPlc p("fbs", {"ORG X0", "OR X1", "LD X2", "OR X3", "ANDLD", "OUT Y0",  //
                         "ORG X0", "AND X1", "LD X2", "AND X3", "ORLD", "OUT Y1"});
    for (int v = 0; v < 16; ++v) {
        const bool x0 = v & 1, x1 = v & 2, x2 = v & 4, x3 = v & 8;
        inputs(p, {x0, x1, x2, x3});
        p.scan();
        EXPECT_EQ(p.y(0), (x0 || x1) && (x2 || x3)) << v;
        EXPECT_EQ(p.y(1), (x0 && x1) || (x2 && x3)) << v;
    }
}

TEST(FatekListing, EdgesLastOneScan) {
    ListingPlc p(
        "fbs", {"ORG TU X0", "OUT M10", "ORG TD X0", "OUT M11", "ORG X1", "AND TU X0", "OUT M12"});
    p.scan();
    EXPECT_FALSE(p.m(10));
    inputs(p, {true, true});
    p.scan();
    EXPECT_TRUE(p.m(10));
    EXPECT_FALSE(p.m(11));
    EXPECT_TRUE(p.m(12));
    p.scan();
    EXPECT_FALSE(p.m(10));  // still ON: no new edge
    EXPECT_FALSE(p.m(12));
    inputs(p, {false, true});
    p.scan();
    EXPECT_FALSE(p.m(10));
    EXPECT_TRUE(p.m(11));
    p.scan();
    EXPECT_FALSE(p.m(11));
}

TEST(FatekListing, OutNotSetRstAndNot) {
    ListingPlc p("fbs", {"ORG X0", "OUT NOT Y0", "ORG X1", "SET M5", "ORG X2", "RST M5", "ORG X0",
                         "NOT", "OUT Y1"});
    p.scan();
    EXPECT_TRUE(p.y(0));
    EXPECT_TRUE(p.y(1));
    inputs(p, {true, true});
    p.scan();
    EXPECT_FALSE(p.y(0));
    EXPECT_FALSE(p.y(1));
    EXPECT_TRUE(p.m(5));
    inputs(p, {false, false});
    p.scan();
    EXPECT_TRUE(p.m(5));  // SET holds
    inputs(p, {false, false, true});
    p.scan();
    EXPECT_FALSE(p.m(5));
}

// TU and TD on their own take the differential of the rung's result so far; SET P and RST P act
// once as their rung turns ON (WinProLadder's words for these, docs/program-language.md).
TEST(FatekListing, DifferentialsAndPulseFormsOfSetAndRst) {
    ListingPlc p("fbs", {"ORG X0", "AND X1", "TU", "OUT M10",  //
                         "ORG X0", "TD", "OUT M11",            //
                         "ORG X2", "SET P M20",                //
                         "ORG X3", "RST M20",                  //
                         "ORG X3", "RST P M21",                //
                         "ORG X2", "SET M21"});
    inputs(p, {true, false});
    p.scan();
    EXPECT_FALSE(p.m(10));  // X0 AND X1 is still OFF
    inputs(p, {true, true});
    p.scan();
    EXPECT_TRUE(p.m(10));  // it turns ON: one scan
    p.scan();
    EXPECT_FALSE(p.m(10));
    EXPECT_FALSE(p.m(11));
    inputs(p, {false, true});
    p.scan();
    EXPECT_TRUE(p.m(11));  // X0 turns OFF: one scan
    p.scan();
    EXPECT_FALSE(p.m(11));

    // SET P M20 while X2 stays ON: RST M20 clears it and it stays clear (a plain SET M21 on the
    // same X2 comes back every scan after RST P cleared it once).
    inputs(p, {false, false, true});
    p.scan();
    EXPECT_TRUE(p.m(20));
    EXPECT_TRUE(p.m(21));
    inputs(p, {false, false, true, true});
    p.scan();
    EXPECT_FALSE(p.m(20));
    EXPECT_TRUE(p.m(21));  // RST P cleared it, then SET M21 set it again in the same scan
    inputs(p, {false, false, true, false});
    p.scan();
    EXPECT_FALSE(p.m(20));  // no new rising edge of X2
    p.set_m(21, false);
    inputs(p, {false, false, false, true});
    p.scan();
    EXPECT_FALSE(p.m(21));
    p.set_m(21, true);
    p.scan();
    EXPECT_TRUE(p.m(21));  // X3 stayed ON: RST P acted only on its rising edge
}

TEST(FatekListing, TemporaryRelaysKeepABranchPoint) {
    // X0 ─┬─ X1 ── Y0
    //     └─ X2 ── Y1
    ListingPlc p("fbs", {"ORG X0", "OUT TR0", "AND X1", "OUT Y0", "LD TR0", "AND X2", "OUT Y1"});
    inputs(p, {true, false, true});
    p.scan();
    EXPECT_FALSE(p.y(0));
    EXPECT_TRUE(p.y(1));
    inputs(p, {false, true, true});
    p.scan();
    EXPECT_FALSE(p.y(0));
    EXPECT_FALSE(p.y(1));
}

TEST(FatekListing, TimerCountsInItsTimeBase) {
    // T0–T49 count 0.01 s: PV 50 is 0.5 s, 50 scans of 10 ms. T50 counts 0.1 s.
    ListingPlc p("fbs", {"ORG X0", "TMR T0 50", "ORG X0", "TMR T50 PV:5", "ORG T0", "OUT Y0"});
    inputs(p, {true});
    p.scan(49);
    EXPECT_FALSE(p.y(0));
    EXPECT_EQ(p.word(Area::TV, 0), 49);
    p.scan();
    EXPECT_TRUE(p.y(0));
    EXPECT_TRUE(p.bit(Area::T, 50));
    EXPECT_EQ(p.word(Area::TV, 50), 5);
    inputs(p, {false});
    p.scan();
    EXPECT_FALSE(p.y(0));  // the rung OFF resets the timer
    EXPECT_EQ(p.word(Area::TV, 0), 0);
}

TEST(FatekListing, CounterCountsRisingEdgesAndRstClearsIt) {
    ListingPlc p("fbs", {"ORG X0", "CTR C0 3", "ORG X1", "RST C0", "ORG C0", "OUT Y0"});
    for (int i = 0; i < 3; ++i) {
        EXPECT_FALSE(p.y(0)) << i;
        inputs(p, {true});
        p.scan();
        inputs(p, {false});
        p.scan();
    }
    EXPECT_TRUE(p.y(0));
    EXPECT_EQ(p.word(Area::CV, 0), 3);
    inputs(p, {false, true});
    p.scan();
    EXPECT_EQ(p.word(Area::CV, 0), 0);
    EXPECT_FALSE(p.bit(Area::C, 0));
}

// The remembered value of every edge is OFF after STOP->RUN as at a start
// (docs/program-language.md): an input ON across the STOP is a rising edge again in the first scan
// in RUN, and one that went OFF during the STOP is no falling edge. They once kept the value of the
// last scan before STOP.
TEST(FatekListing, EdgesStartOverAtStopToRun) {
    ListingPlc p("fbs", {"ORG X0", "CTR C0 100",                           // the counter's own edge
                         "ORG TU X0", "OUT M10", "ORG M10", "CTR C1 100",  // a TU contact
                         "ORG X0", "TU", "OUT M11", "ORG M11", "CTR C2 100",  // TU on the rung
                         "ORG X0", "SET P M20",                               // SET's pulse form
                         "ORG X0", "FUN8P MOV S:R10 D:R11",                   // MOVP
                         "ORG TD X1", "OUT M12", "ORG M12", "CTR C3 100"});   // a TD contact
    p.set_r(10, 7);
    inputs(p, {true, true});
    p.scan(3);
    auto counts = [&] {
        return std::vector<int>{p.word(Area::CV, 0), p.word(Area::CV, 1), p.word(Area::CV, 2),
                                p.word(Area::CV, 3)};
    };
    EXPECT_EQ(counts(), (std::vector<int>{1, 1, 1, 0}));
    EXPECT_TRUE(p.bit(Area::M, 20));
    EXPECT_EQ(p.r(11), 7);
    p.plc.engine().set_running(false);
    p.scan(2);
    p.set(Area::M, 20, false);
    p.set_r(11, 0);
    inputs(p, {true, false});  // X1 goes OFF while the program does not run
    p.scan(2);
    p.plc.engine().set_running(true);
    p.scan();
    EXPECT_EQ(counts(), (std::vector<int>{2, 2, 2, 0}));
    EXPECT_TRUE(p.bit(Area::M, 20));
    EXPECT_EQ(p.r(11), 7);
    p.scan(3);
    EXPECT_EQ(counts(), (std::vector<int>{2, 2, 2, 0})) << "one edge, not one a scan";
}

// A disabled discrete (FATEK command 42) is not changed by the program (docs/profile-fbs.md,
// "FATEK protocol"): the rungs after an OUT to it see what the master put there, as do a word
// written over it (WM16 holds M16-M31) and the scan after. It once took the program's value
// until the scan's end.
TEST(FatekListing, RungsSeeWhatAMasterPutInADisabledDiscrete) {
    ListingPlc p("fbs", {"ORG X0", "OUT M5", "ORG M5", "OUT M6",  //
                         "ORG M1926", "FUN8 MOV S:R0 D:WM16", "ORG M20", "OUT M7"});
    engine::Holds& h = p.plc.engine().holds();
    ASSERT_TRUE(h.set(Area::M, 5, true));
    ASSERT_TRUE(h.set(Area::M, 20, true));
    p.set(Area::M, 5, true);  // the master sets them; X0 is OFF and R0 is 0
    p.set(Area::M, 20, true);
    p.set_r(0, 0x0003);
    p.scan();
    EXPECT_TRUE(p.bit(Area::M, 5));
    EXPECT_TRUE(p.bit(Area::M, 6)) << "the rung after the OUT saw the forced M5";
    EXPECT_TRUE(p.bit(Area::M, 20));
    EXPECT_TRUE(p.bit(Area::M, 7)) << "the rung after the MOV saw the forced M20";
    EXPECT_TRUE(p.bit(Area::M, 16));
    EXPECT_TRUE(p.bit(Area::M, 17));
    EXPECT_FALSE(p.bit(Area::M, 18));
    // Enabled again, the program drives them.
    h.set(Area::M, 5, false);
    h.set(Area::M, 20, false);
    p.scan();
    EXPECT_FALSE(p.bit(Area::M, 5));
    EXPECT_FALSE(p.bit(Area::M, 6));
    EXPECT_FALSE(p.bit(Area::M, 20));
    EXPECT_FALSE(p.bit(Area::M, 7));
}

// A timer's or counter's contact a master disabled and set is read so by the rungs after the
// TMR or CTR, whose own write of it (OFF: X0 is OFF) passes it by; it once read OFF there.
TEST(FatekListing, RungsSeeADisabledTimerOrCounterContactAsTheMasterSetIt) {
    ListingPlc p("fbs", {"ORG X0", "TMR T0 100", "ORG T0", "OUT M6",  //
                         "ORG X0", "CTR C0 10", "ORG C0", "OUT M7"});
    engine::Holds& h = p.plc.engine().holds();
    ASSERT_TRUE(h.set(Area::T, 0, true));
    ASSERT_TRUE(h.set(Area::C, 0, true));
    p.set(Area::T, 0, true);
    p.set(Area::C, 0, true);
    p.scan(2);
    EXPECT_TRUE(p.bit(Area::T, 0));
    EXPECT_TRUE(p.bit(Area::M, 6));
    EXPECT_TRUE(p.bit(Area::C, 0));
    EXPECT_TRUE(p.bit(Area::M, 7));
}

TEST(FatekListing, FunctionTakesItsEnableFromTheRung) {
    // FUN8 MOV written three ways, and its pulse form.
    ListingPlc p("fbs", {"ORG X0", "AND X1", "FUN8 MOV S:R0 D:R10", "ORG X0", "FUN 8 MOV",
                         "  S: R1", "  D: R11", "ORG X0", "8.MOV S:R2 D:R12", "ORG X0",
                         "FUN8P MOV S:R13 D:R13", "ORG X0", "MOVP S:R20 D:R14"});
    p.set_r(0, 7);
    p.set_r(1, 8);
    p.set_r(2, 9);
    p.set_r(20, 1);
    p.scan();
    EXPECT_EQ(p.r(10), 0);
    EXPECT_EQ(p.r(11), 0);
    inputs(p, {true});
    p.scan();
    EXPECT_EQ(p.r(10), 0);  // X1 OFF
    EXPECT_EQ(p.r(11), 8);
    EXPECT_EQ(p.r(12), 9);
    EXPECT_EQ(p.r(14), 1);
    p.set_r(20, 2);
    p.scan();
    EXPECT_EQ(p.r(14), 1);  // the pulse form moved once, at the rising edge
    inputs(p, {true, true});
    p.scan();
    EXPECT_EQ(p.r(10), 7);
}

TEST(FatekListing, StepNumbersOfPrintProgramReadBack) {
    const std::vector<std::string> lines = {
        "ORG X0   ; start",    "OR Y0", "AND NOT X1", "OUT Y0", "ORG M1926",
        "FUN 8 MOV S:R0 D:R1", "END"};
    const auto cfg = config::parse_config(testing::listing_config("fbs", lines), "il.yaml");
    const std::string printed = daemon::print_program(cfg);
    EXPECT_EQ(printed,
              "0001  ORG X0\n0002  OR Y0\n0003  AND NOT X1\n0004  OUT Y0\n0005  ORG M1926\n"
              "0006  MOV S:R0 D:R1\n0007  END\n");
    // What it prints is a program too, and the same one.
    std::vector<std::string> again;
    std::size_t at = 0;
    while (at < printed.size()) {
        const auto end = printed.find('\n', at);
        again.push_back(printed.substr(at, end - at));
        at = end + 1;
    }
    const auto cfg2 = config::parse_config(testing::listing_config("fbs", again), "il.yaml");
    EXPECT_EQ(daemon::print_program(cfg2), printed);
}

TEST(FatekListing, RefusalsNameLineColumnAndMnemonic) {
    expect_listing_error("fbs", {"LD X0", "OUT Y0"}, 1, 8,
                         "LD: no network is open (a network starts with ORG)");
    expect_listing_error("fbs", {"ORG X0", "LD X1", "OUT Y0"}, 3, 8,
                         "OUT: 1 block opened by LD not joined (ANDLD, ORLD)");
    expect_listing_error("fbs", {"ORG X0", "ANDLD"}, 2, 8, "ANDLD: no block opened by LD");
    expect_listing_error("fbs", {"ORG X0", "ORG X1", "OUT Y0"}, 2, 8,
                         "ORG: the rung before (from il.yaml:4:8) has no output");
    expect_listing_error("fbs", {"ORG X0"}, 1, 8, "the rung from here has no output");
    expect_listing_error("fbs", {"ORG X0", "FOO Y0"}, 2, 8,
                         "unknown instruction 'FOO' (not in WinProladder's mnemonic view)");
    expect_listing_error("fbs", {"ORG X0", "FUN 99"}, 2, 8, "FUN 99: no such function");
    // A timer or counter without its preset is told the form this dialect writes (it was told
    // the VB's OUT T0 K10).
    expect_listing_error("fbs", {"ORG X0", "OUT T0"}, 2, 8,
                         "OUT: T0 needs its preset (TMR T0 K10)");
    expect_listing_error("fbs", {"ORG X0", "OUT C3"}, 2, 8,
                         "OUT: C3 needs its preset (CTR C3 K10)");
    // A stray colon: the word is quoted as written (it was "operand 'y0' has no value").
    expect_listing_error("fbs", {"ORG X0", "OUT Y0:"}, 2, 12,
                         "OUT: operand 'Y0:' has no value after it (a word ending in ':' names");
    // A number no integer holds is a constant out of range, not "expected a register" or
    // "expected 1 word(s) in D, R".
    expect_listing_error("fbs", {"ORG X0", "TMR T0 99999999999999999999999"}, 2, 15,
                         "99999999999999999999999 is out of range 0..32767");
    expect_listing_error("fbs", {"ORG X0", "CTR C0 99999999999999999999"}, 2, 15,
                         "99999999999999999999 is out of range 0..32767");
    expect_listing_error("fbs", {"ORG X0", "CTR C200 -99999999999999999999"}, 2, 17,
                         "-99999999999999999999 is out of range -2147483648..2147483647");
    expect_listing_error("fbs", {"ORG X0", "FUN8 MOV S:99999999999999999999 D:R0"}, 2, 19,
                         "MOV.s: constant out of 16-bit range");
    expect_listing_error("fbs", {"ORG X0", "FUN8 MOV S:R0 D:R1 EN:M0"}, 2, 30,
                         "MOV: EN is the rung's result; leave `en` out");
    expect_listing_error("fbs", {"ORG X0", "MOV S:R0 D:Q1"}, 2, 19, "MOV.d");
    expect_listing_error("fbs", {"ORG D0", "OUT Y0"}, 1, 12, "ORG.s");
    expect_listing_error("fbs", {"ORG X0", "OUT X1"}, 2, 12, "OUT.d: expected a Y, M or S");
    expect_listing_error("fbs", {"ORG X0", "OUT TR40"}, 2, 12, "OUT: TR40: there are 40");
    expect_listing_error("fbs", {"ORG X0", "TMR T0"}, 2, 8, "TMR: expected 2 operands (t k)");
    expect_listing_error("fbs", {"ORG X0", "OUT Y0", "END", "ORG X1"}, 4, 8, "ORG: after END");
    expect_listing_error("fbs", {"  S: R0"}, 1, 10, "without a function instruction above it");
    // The vb's spellings are not WinProladder's.
    expect_listing_error("fbs", {"LDI X0"}, 1, 8, "unknown instruction 'LDI'");
}

TEST(FatekListing, DoubleCoilIsAWarningNotARefusal) {
    const auto cfg = config::parse_config(
        testing::listing_config("fbs",
                                {"ORG X0", "OUT Y0", "ORG X1", "OUT Y0", "ORG X2", "SET Y0"}),
        "il.yaml");
    std::vector<std::string> w;
    daemon::build_program(cfg, nullptr, &w);
    ASSERT_EQ(w.size(), 1U);
    EXPECT_EQ(w[0],
              "il.yaml:7:8: OUT: double coil: Y0 is driven at il.yaml:5:8 too; the last one in "
              "the scan wins");
    ListingPlc p("fbs", {"ORG X0", "OUT Y0", "ORG X1", "OUT Y0"});
    inputs(p, {true, false});
    p.scan();
    EXPECT_FALSE(p.y(0));  // the last OUT wins, as on the PLC
}

TEST(FatekListing, FbHasItsOwnFunctions) {
    ListingPlc p("fb", {"ORG X0", "FUN8 MOV S:K5 D:R0"});
    inputs(p, {true});
    p.scan();
    EXPECT_EQ(p.r(0), 5);
    // FB manual FUN86: a TPCTL needs the FUN85 TPSNS, in a listing as in entries.
    expect_listing_error("fb", {"ORG X0", "FUN86 TPCTL"}, 2, 8, "TPCTL needs a TPSNS");
    // TPCTL is FUN86 in both; TP4 is the fb's alone.
    expect_listing_error("fbs", {"ORG X0", "FUN72 TP4"}, 2, 8, "FUN 72: no such function");
}

// ---- vb: the FX family's instruction list ----

TEST(VbListing, ContactsAndBlocks) {
    // Y0 = (X0 AND NOT X1) OR (X2 AND X3); Y1 = NOT X0 OR NOT X1.
    ListingPlc p("vb", {"LD X0", "ANI X1", "LD X2", "AND X3", "ORB", "OUT Y0",  //
                        "LDI X0", "ORI X1", "OUT Y1",                           //
                        "LD X0", "OR X1", "LD X2", "OR X3", "ANB", "OUT Y2"});
    for (int v = 0; v < 16; ++v) {
        const bool x0 = v & 1, x1 = v & 2, x2 = v & 4, x3 = v & 8;
        inputs(p, {x0, x1, x2, x3});
        p.scan();
        EXPECT_EQ(p.y(0), (x0 && !x1) || (x2 && x3)) << v;
        EXPECT_EQ(p.y(1), !x0 || !x1) << v;
        EXPECT_EQ(p.y(2), (x0 || x1) && (x2 || x3)) << v;
    }
}

TEST(VbListing, BranchStackMpsMrdMpp) {
    // X0 ─┬─ X1 ── Y0
    //     ├─ X2 ── Y1
    //     └─ X3 ── Y2
    ListingPlc p("vb", {"LD X0", "MPS", "AND X1", "OUT Y0", "MRD", "AND X2", "OUT Y1", "MPP",
                        "AND X3", "OUT Y2"});
    for (int v = 0; v < 16; ++v) {
        const bool x0 = v & 1, x1 = v & 2, x2 = v & 4, x3 = v & 8;
        inputs(p, {x0, x1, x2, x3});
        p.scan();
        EXPECT_EQ(p.y(0), x0 && x1) << v;
        EXPECT_EQ(p.y(1), x0 && x2) << v;
        EXPECT_EQ(p.y(2), x0 && x3) << v;
    }
}

TEST(VbListing, EdgeContactsAndPulses) {
    ListingPlc p("vb", {"LDP X0", "OUT M0", "LDF X0", "OUT M1", "LD X1", "ANDP X0", "OUT M2",
                        "LD X1", "ORF X0", "OUT M3", "LD X0", "PLS M4", "LD X0", "PLF M5"});
    inputs(p, {true, false});
    p.scan();  // an input already ON in the first scan is an edge (FX)
    EXPECT_TRUE(p.m(0));
    EXPECT_TRUE(p.m(4));
    EXPECT_FALSE(p.m(1));
    p.scan();
    EXPECT_FALSE(p.m(0));
    EXPECT_FALSE(p.m(4));
    inputs(p, {false, false});
    p.scan();
    EXPECT_TRUE(p.m(1));
    EXPECT_TRUE(p.m(3));
    EXPECT_TRUE(p.m(5));
    p.scan();
    EXPECT_FALSE(p.m(1));
    EXPECT_FALSE(p.m(5));
    inputs(p, {true, true});
    p.scan();
    EXPECT_TRUE(p.m(2));
}

TEST(VbListing, TimersAndCountersAsOutWithK) {
    // T0 counts 100 ms (FX2N): K5 is 0.5 s, 50 scans of 10 ms.
    ListingPlc p("vb", {"LD X0", "OUT T0 K5", "LD T0", "OUT Y0", "LD X1", "OUT C0 K2", "LD C0",
                        "OUT Y1", "LD X2", "RST C0"});
    inputs(p, {true});
    p.scan(49);
    EXPECT_FALSE(p.y(0));
    p.scan();
    EXPECT_TRUE(p.y(0));
    for (int i = 0; i < 2; ++i) {
        inputs(p, {true, true});
        p.scan();
        inputs(p, {true, false});
        p.scan();
    }
    EXPECT_TRUE(p.y(1));
    inputs(p, {true, false, true});
    p.scan();
    p.scan();
    EXPECT_FALSE(p.y(1));
}

TEST(VbListing, MasterControlHoldsItsRungsOff) {
    // Between MC N0 and MCR N0: an OUT turns off, a timer resets, a SET keeps.
    ListingPlc p("vb", {"LD X0", "MC N0 M100", "LD X1", "OUT Y0", "LD X1", "SET Y1", "LD X1",
                        "OUT T0 K100", "LDI X2", "OUT Y3", "MCR N0", "LD X1", "OUT Y2"});
    inputs(p, {true, true});
    p.scan(3);
    EXPECT_TRUE(p.m(100));
    EXPECT_TRUE(p.y(0));
    EXPECT_TRUE(p.y(1));
    EXPECT_TRUE(p.y(3));
    EXPECT_EQ(p.word(Area::TV, 0), 0);  // 30 ms: no whole 100 ms yet
    p.scan(10);
    EXPECT_EQ(p.word(Area::TV, 0), 1);
    inputs(p, {false, true});
    p.scan();
    EXPECT_FALSE(p.m(100));
    EXPECT_FALSE(p.y(0));
    EXPECT_TRUE(p.y(1));
    EXPECT_FALSE(p.y(3));  // LDI of an OFF input: still held OFF
    EXPECT_EQ(p.word(Area::TV, 0), 0);
    EXPECT_TRUE(p.y(2));  // after MCR the rungs run again
}

TEST(VbListing, InvertCompareContactsAndEnd) {
    ListingPlc p("vb", {"LD X0", "INV", "OUT Y0", "LD< D0 K10", "OUT Y1", "LD X1", "AND<> D1 D2",
                        "OUT Y2", "LD>= D0 K-5", "OR= D1 K3", "OUT Y3", "END"});
    p.set_word(Area::D, 0, static_cast<std::uint16_t>(-6));
    p.set_word(Area::D, 1, 3);
    p.set_word(Area::D, 2, 3);
    inputs(p, {false, true});
    p.scan();
    EXPECT_TRUE(p.y(0));
    EXPECT_TRUE(p.y(1));   // −6 < 10, signed
    EXPECT_FALSE(p.y(2));  // D1 = D2
    EXPECT_TRUE(p.y(3));   // −6 ≥ −5 is false, D1 = 3
    p.set_word(Area::D, 2, 4);
    p.set_word(Area::D, 1, 4);
    p.set_word(Area::D, 0, 20);
    p.scan();
    EXPECT_FALSE(p.y(1));
    EXPECT_FALSE(p.y(2));
    EXPECT_TRUE(p.y(3));
}

TEST(VbListing, AppliedInstructionsByNameNumberAndPulse) {
    ListingPlc p("vb", {"LD X0", "MOV K7 D0", "LD X0", "FNC12 K8 D1", "LD X0", "MOVP D10 D2",
                        "LD X0", "FNC 12P D10 D3", "LD X0", "WOR D0 D1 D4"});
    p.set_word(Area::D, 10, 1);
    inputs(p, {true});
    p.scan();
    EXPECT_EQ(p.d(0), 7);
    EXPECT_EQ(p.d(1), 8);
    EXPECT_EQ(p.d(2), 1);
    EXPECT_EQ(p.d(3), 1);
    EXPECT_EQ(p.d(4), 15);
    p.set_word(Area::D, 10, 2);
    p.scan();
    EXPECT_EQ(p.d(2), 1);  // pulse forms: once per rising edge
    EXPECT_EQ(p.d(3), 1);
}

// In a listing, an instruction is known by its step: D9069 names the step of an operation
// error, and the console's loop is "PID D101 (step 4)".
TEST(VbListing, AnInstructionIsKnownByItsStep) {
    ListingPlc p("vb", {"LD X0", "OUT Y0", "LD M0", "PID D100 D101 D200 D102"});
    engine::Loops loops;
    for (const auto& i : p.plc.engine().program()) i->loops(p.plc.image(), loops);
    ASSERT_EQ(loops.size(), 1u);
    EXPECT_EQ(loops[0].name, "PID D101 (step 4)");
    p.set_m(0, true);  // S3+0, the sampling time, is 0: an operand error
    p.scan(3);
    EXPECT_TRUE(p.m(9067));
    EXPECT_NE(p.d(9067), 0);
    EXPECT_EQ(p.d(9069), 4);
}

// NOP is a step of its own: it does nothing, counts in the step numbers, stands anywhere (after
// END too, as an FX program's unused steps) and takes no operand.
TEST(VbListing, NopIsAStepThatDoesNothing) {
    ListingPlc p("vb", {"NOP", "LD X0", "NOP", "OUT Y0", "LD X1", "PLS M0", "END", "NOP", "NOP"});
    inputs(p, {true, true});
    p.scan();
    EXPECT_TRUE(p.y(0));
    EXPECT_TRUE(p.m(0));
    const auto printed = daemon::print_program(p.plc.config());
    EXPECT_NE(printed.find("0003  NOP\n0004  OUT Y0\n"), std::string::npos) << printed;
    EXPECT_NE(printed.find("0007  END\n0008  NOP\n0009  NOP\n"), std::string::npos) << printed;
    expect_listing_error("vb", {"LD X0", "NOP M0", "OUT Y0"}, 2, 8, "NOP: takes no operand");
}

TEST(VbListing, CmpPulseFormComparesOncePerRisingEdge) {
    ListingPlc p("vb", {"LD X0", "CMPP D0 D1 Y0"});
    p.set(Area::X, 0, true);
    p.set_word(Area::D, 0, 2);
    p.scan();
    EXPECT_TRUE(p.y(0));
    p.set_word(Area::D, 1, 5);
    p.scan();
    EXPECT_TRUE(p.y(0));  // no new edge: not compared again
    p.set(Area::X, 0, false);
    p.scan();
    p.set(Area::X, 0, true);
    p.scan();
    EXPECT_FALSE(p.y(0));
    EXPECT_TRUE(p.y(2));
}

TEST(VbListing, RefusalsNameLineColumnAndMnemonic) {
    expect_listing_error("vb", {"LD X0", "MPS", "OUT Y0", "LD X1", "OUT Y1"}, 4, 8,
                         "LD: a new rung starts with 1 result(s) left on the branch stack");
    expect_listing_error("vb", {"LD X0", "MRD"}, 2, 8, "MRD: the branch stack is empty");
    expect_listing_error("vb", {"LD X0", "MC N1 M0", "LD X1", "MC N0 M1"}, 4, 11,
                         "MC: N0 inside N1");
    expect_listing_error("vb", {"LD X0", "MC N0 M0", "LD X1", "OUT Y0"}, 2, 8, "MC N0 has no MCR");
    expect_listing_error("vb", {"MCR N2"}, 1, 12, "MCR: no MC N2 is open");
    expect_listing_error("vb", {"LD X0", "MC N9 M0"}, 2, 11, "expected a nesting level N0");
    expect_listing_error("vb", {"LD X8", "OUT Y0"}, 1, 11, "LD.s");  // X counts in octal
    expect_listing_error("vb", {"LD X0", "MOV K1 D0 D1"}, 2, 18,
                         "MOV: takes 2 operands (s d) written in order");
    expect_listing_error("vb", {"LD X0", "PIDP D0 D1 D2 D3"}, 2, 8, "unknown instruction 'PIDP'");
    expect_listing_error("vb", {"LD X0", "ORG X1"}, 2, 8, "unknown instruction 'ORG'");
    expect_listing_error("vb", {"LD X0", "OUT T0"}, 2, 8, "OUT: T0 needs its preset (OUT T0 K10)");
    // The profile's checks of the program see a listing's instructions too.
    expect_listing_error("vb", {"LD M0", "MBUS D1000 D100"}, 2, 8,
                         "MBUS: the program polls slaves, but the config has no mbus: section");
}

// docs/program-language.md: `;` or `//` starts a comment; `//` touching an operand was read as
// part of it ("expected a Y, M or S output, got 'Y1//x'").
TEST(Listing, ACommentEndsTheWordItTouches) {
    const Dialect& fbs = *testing::profile("fbs").listing();
    for (const char* text : {"OUT Y1//x", "OUT Y1;x", "OUT Y1 // x", "OUT Y1,//x"}) {
        const auto st = read_listing({ListingLine{text, {"c.il", 1, 1}}}, fbs);
        ASSERT_EQ(st.size(), 1u) << text;
        ASSERT_EQ(st[0].operands.size(), 1u) << text;
        EXPECT_EQ(st[0].operands[0].text, "Y1") << text;
    }
    // One slash is no comment: the operand keeps it, and its refusal quotes it.
    expect_listing_error("fbs", {"ORG X0", "OUT Y1/x"}, 2, 12, "got 'Y1/x'");
}

// Each named operand was compared with every one before it: 50,000 on operand lines took 20 s
// to refuse and 100,000 on one line 94 s. A statement is refused at the operand past the most
// any instruction takes.
TEST(Listing, AStatementOfMoreOperandsThanAnyInstructionTakesIsRefusedThere) {
    const Dialect& fbs = *testing::profile("fbs").listing();
    std::string line = "FUN86 TPCTL";
    for (int i = 0; i < 100'000; ++i) line += " k" + std::to_string(i) + ":" + std::to_string(i);
    try {
        read_listing({ListingLine{line, {"one.il", 2, 1}}}, fbs);
        ADD_FAILURE() << "no refusal";
    } catch (const BindError& e) {
        EXPECT_EQ(e.where().line, 2);
        // k32:32 stands after "FUN86 TPCTL" and 32 operands of 5 or 6 characters and a blank.
        EXPECT_EQ(e.where().column, static_cast<int>(line.find(" k32:") + 2));
        EXPECT_NE(std::string(e.what()).find("TPCTL: more than 32 operands"), std::string::npos)
            << e.what();
    }
    // On operand lines below the function, the line that crosses the bound.
    std::vector<ListingLine> lines{{"ORG X0", {"lines.il", 1, 1}},
                                   {"FUN8 MOV", {"lines.il", 2, 1}}};
    for (int i = 0; i < 50'000; ++i) {
        lines.push_back(
            {"k" + std::to_string(i) + ": " + std::to_string(i), {"lines.il", i + 3, 1}});
    }
    try {
        read_listing(lines, fbs);
        ADD_FAILURE() << "no refusal";
    } catch (const BindError& e) {
        EXPECT_EQ(e.where().line, 35);  // k32
        EXPECT_EQ(e.where().column, 1);
    }
    // At the bound, the statement reads (its operands are the instruction's to check).
    line = "FUN86 TPCTL";
    for (int i = 0; i < 32; ++i) line += " k" + std::to_string(i) + ":1";
    EXPECT_EQ(read_listing({ListingLine{line, {"one.il", 1, 1}}}, fbs).at(0).named.size(), 32u);
}

TEST(Listing, SizesAreBoundedAndWarningsCounted) {
    const Dialect& vb = *testing::profile("vb").listing();
    std::vector<ListingLine> lines(kMaxStatements - 1, ListingLine{"LD X0", {"big.il", 1, 1}});
    lines.push_back({"OUT Y0", {"big.il", 100'000, 1}});
    EXPECT_EQ(read_listing(lines, vb).size(), kMaxStatements);  // at the bound
    lines.push_back({"OUT Y1", {"big.il", 100'002, 3}});
    try {
        read_listing(lines, vb);
        ADD_FAILURE() << "no refusal";
    } catch (const BindError& e) {
        EXPECT_EQ(e.where().line, 100'002);
        EXPECT_EQ(e.where().column, 3);
        EXPECT_NE(std::string(e.what()).find("more than 100000 statements"), std::string::npos);
    }
    // A program file of more lines than any program needs is refused at the line that crosses
    // the limit (docs/program-language.md; it was refused at its `file:`).
    const auto dir = std::filesystem::temp_directory_path() / "plcemu-listing-test";
    std::filesystem::create_directories(dir);
    {
        std::ofstream f(dir / "long.il");
        for (int i = 0; i <= 400'000; ++i) f << ";\n";
    }
    testing::expect_config_error(testing::config_failure([&] {
                                     config::parse_config("profile: vb\nprogram: {file: long.il}\n",
                                                          (dir / "p.yaml").string());
                                 }),
                                 (dir / "long.il").string(), 400'001, 1,
                                 "program.file: more than 400000 lines; refused");
    std::filesystem::remove_all(dir);
    // Twelve coils driven twice: ten warnings, then one counting the rest.
    std::vector<std::string> twice;
    for (int i = 0; i < 12; ++i) twice.insert(twice.end(), {"LD X0", "OUT Y0"});
    std::vector<std::string> w;
    daemon::build_program(config::parse_config(testing::listing_config("vb", twice), "il.yaml"),
                          nullptr, &w);
    ASSERT_EQ(w.size(), kMaxListingWarnings + 1);
    EXPECT_EQ(w.back(), "il.yaml:4:8: 1 more double coils in this program");
}

TEST(Listing, AProgramIsEntriesOrAListingNotBoth) {
    testing::expect_config_error(
        testing::config_failure([] {
            config::parse_config("profile: fbs\nprogram: {file: a.il, il: ['ORG X0']}\n", "p.yaml");
        }),
        "p.yaml", 2, 10, "program: expected either 'file'");
    testing::expect_config_error(
        testing::config_failure([] {
            config::parse_config("profile: fbs\nprogram: {file: /nonexistent/a.il}\n", "p.yaml");
        }),
        "p.yaml", 2, 17, "program.file: cannot open the program file /nonexistent/a.il");
    testing::expect_config_error(
        testing::config_failure(
            [] { config::parse_config("profile: fbs\nprogram: {il: 'ORG X0'}\n", "p.yaml"); }),
        "p.yaml", 2, 15, "program.il: expected a list of lines");
}

}  // namespace
}  // namespace plcemu::instructions
