// FNC149 MBUS (VB manual FNC149, "MODBUS Communication"; docs/profile-vb.md, "FNC149 MBUS"): one
// test per rule — the table at S1 and its re-reading, the function codes, one request in flight,
// completions applied at the instruction's next execution, the seven set checks in order with
// their statuses, S2+0…S2+3, the M9199 pulse per pass, the D9129 time-out, exception and
// malformed replies, EN falling, one MBUS per program and the `mbus:` section. The slave side is
// a scripted outbound link (tests/support/fake_outbound.hpp).

#include <gtest/gtest.h>

#include <chrono>
#include <cstdint>
#include <string>
#include <vector>

#include "plcemu/config/config.hpp"
#include "plcemu/image/image.hpp"
#include "plcemu/profiles/profile.hpp"
#include "profiles/vb/specials.hpp"
#include "support/config_errors.hpp"
#include "support/fake_outbound.hpp"
#include "support/vb_plc.hpp"

namespace plcemu::profiles::vb {
namespace {

using engine::OutboundCompletion;
using engine::OutboundRequest;
using image::Area;
using testing::FakeOutbound;
using testing::VbPlc;
using W = std::vector<std::uint16_t>;

const std::string kMbusSection = "mbus: {tcp: {host: 127.0.0.1, port: 5021}}\n";
const std::string kProgram = "  - MBUS: {en: M0, s1: D1000, s2: D100}\n";

// A VB running MBUS over a scripted link, with a table of sets of 7 words at D1000 (kept here:
// the link is this test's own).
struct Rig {
    explicit Rig(const std::string& program = kProgram, const std::string& head = "")
        : p(program, kMbusSection + head) {
        p.plc.engine().set_outbound(&link);
    }
    // The table: N, then the sets.
    void table(const std::vector<W>& sets) {
        p.set_word(Area::D, 1000, static_cast<std::uint16_t>(sets.size()));
        std::uint32_t d = 1001;
        for (const auto& s : sets) {
            for (auto w : s) p.set_word(Area::D, d++, w);
        }
    }
    void enable(bool on = true) { p.set(Area::M, 0, on); }
    std::uint16_t status() { return p.word(Area::D, 100); }
    bool pass_pulse() { return p.bit(Area::M, special::kMbusPass); }

    FakeOutbound link;
    VbPlc p;
};

// The manual's example sets: read 10 words of station 5 from 40000 into D2000; write D2010–D2014
// to station 2 at 41000; write D2015 to station 3 at 42000.
const W kRead5{5, 1, 10, 13, 2000, 4, 0};
const W kWrite2{2, 2, 5, 13, 2010, 4, 1000};
const W kWrite3{3, 3, 1, 13, 2015, 4, 2000};

// A responder that answers reads with 100 + address + i and acknowledges writes.
OutboundCompletion echo_slave(const OutboundRequest& r) {
    OutboundCompletion c;
    c.status = engine::OutboundStatus::Reply;
    for (std::size_t i = 0; i < r.quantity; ++i) {
        c.values[i] = static_cast<std::uint16_t>(100 + r.address + i);
    }
    return c;
}

// VB manual FNC149 example, set 1: "read the data in 40000 ~ 40009 of Slave station #5 and put
// they to D2000 ~ D2009".
TEST(Mbus, ReadSetSendsFc03AndPutsTheReplyInTheMasterDevices) {
    Rig r;
    r.table({kRead5});
    r.enable();
    r.p.scan();
    ASSERT_EQ(r.link.sent.size(), 1u);
    const OutboundRequest& q = r.link.sent[0];
    EXPECT_EQ(q.station, 5);
    EXPECT_EQ(q.function, 3);
    EXPECT_EQ(q.address, 0);
    EXPECT_EQ(q.quantity, 10);
    r.link.reply({1, 2, 3, 4, 5, 6, 7, 8, 9, 10});
    EXPECT_EQ(r.p.d(2000, 10), W(10, 0)) << "nothing lands before the next execution";
    r.p.scan();
    EXPECT_EQ(r.p.d(2000, 10), (W{1, 2, 3, 4, 5, 6, 7, 8, 9, 10}));
    EXPECT_EQ(r.status(), 0);
}

// VB manual FNC149 example, sets 2 and 3: the data to write are the master's at the scan the
// request is sent.
TEST(Mbus, WriteSetsSendFc16AndFc06WithTheDataSampledWhenSent) {
    Rig r;
    r.table({kWrite2, kWrite3});
    r.p.set_d(2010, {11, 12, 13, 14, 15, 16});
    r.enable();
    r.p.scan();
    ASSERT_EQ(r.link.sent.size(), 1u);
    r.p.set_word(Area::D, 2010, 999);  // after sending: not in this request
    EXPECT_EQ(r.link.sent[0].function, 16);
    EXPECT_EQ(r.link.sent[0].station, 2);
    EXPECT_EQ(r.link.sent[0].address, 1000);
    EXPECT_EQ(r.link.sent[0].quantity, 5);
    EXPECT_EQ(W(r.link.sent[0].values.begin(), r.link.sent[0].values.begin() + 5),
              (W{11, 12, 13, 14, 15}));
    r.link.reply();
    r.p.scan();
    ASSERT_EQ(r.link.sent.size(), 2u);
    EXPECT_EQ(r.link.sent[1].function, 6);
    EXPECT_EQ(r.link.sent[1].station, 3);
    EXPECT_EQ(r.link.sent[1].address, 2000);
    EXPECT_EQ(r.link.sent[1].quantity, 1);
    EXPECT_EQ(r.link.sent[1].values[0], 16);
}

// Decision (docs/profile-vb.md, function codes): command × slave type → FC01/02/03/04, FC15/16,
// FC05/06; bits travel as 0/1 and FC05 carries one bit.
TEST(Mbus, FunctionCodeTable) {
    struct Case {
        W set;
        int fc;
    };
    const std::vector<Case> cases{
        {{1, 1, 8, 3, 0, 0, 0}, 1},  {{1, 1, 8, 3, 0, 1, 0}, 2},  {{1, 1, 2, 13, 0, 3, 0}, 4},
        {{1, 1, 2, 13, 0, 4, 0}, 3}, {{1, 2, 8, 2, 0, 0, 0}, 15}, {{1, 2, 2, 13, 0, 4, 0}, 16},
        {{1, 3, 0, 3, 7, 0, 0}, 5},  {{1, 3, 0, 10, 0, 4, 0}, 6},
    };
    for (const auto& c : cases) {
        Rig r;
        r.table({c.set});
        r.enable();
        r.p.scan();
        ASSERT_EQ(r.link.sent.size(), 1u);
        EXPECT_EQ(r.link.sent[0].function, c.fc) << "command " << c.set[1] << " type " << c.set[5];
    }
}

TEST(Mbus, BitWritesCarryTheMasterBitsAsZeroOrOne) {
    Rig r;
    r.table({{1, 2, 4, 2, 10, 0, 0}, {1, 3, 0, 3, 7, 0, 9}});  // Y10–Y13 (octal), then M7
    r.p.set(Area::Y, 8, true);
    r.p.set(Area::Y, 10, true);
    r.p.set(Area::M, 7, true);
    r.link.responder = echo_slave;
    r.enable();
    r.p.scan(2);
    ASSERT_EQ(r.link.sent.size(), 2u);
    EXPECT_EQ(W(r.link.sent[0].values.begin(), r.link.sent[0].values.begin() + 4), (W{1, 0, 1, 0}));
    EXPECT_EQ(r.link.sent[1].values[0], 1);
}

// X and Y numbers are written as their octal digits (VB manual FNC149 "X20"): 20 is X20, the
// 17th input; a bit read lands there.
TEST(Mbus, MasterXYNumbersAreOctalDigits) {
    Rig r;
    r.table({{1, 1, 2, 2, 20, 0, 0}});  // read 2 coils into Y20, Y21
    r.enable();
    r.p.scan();
    r.link.reply({1, 1});
    r.p.scan();
    EXPECT_TRUE(r.p.bit(Area::Y, 16));
    EXPECT_TRUE(r.p.bit(Area::Y, 17));
    EXPECT_FALSE(r.p.bit(Area::Y, 20));
}

// FNC149 (docs/profile-vb.md, "The cycle"): "Exactly one request is in flight": nothing more is
// sent while it waits.
TEST(Mbus, OneRequestInFlight) {
    Rig r;
    r.table({kRead5, kWrite2, kWrite3});
    r.enable();
    r.p.scan(20);
    EXPECT_EQ(r.link.sent.size(), 1u);
    EXPECT_EQ(r.p.word(Area::D, 101), 1) << "S2+1: set 1 in progress";
    r.link.reply({});
    r.p.scan();
    EXPECT_EQ(r.link.sent.size(), 2u);
    EXPECT_EQ(r.p.word(Area::D, 101), 2) << "S2+1: set 2 in progress";
}

// With a reply faster than the scan each set takes one scan; after the last, M9199 is ON for one
// scan and S2+2 counts the pass, then set 1 again (VB manual FNC149).
TEST(Mbus, M9199PulsesOneScanPerPassAndS2Plus2CountsPasses) {
    Rig r;
    r.table({kRead5, kWrite2, kWrite3});
    r.link.responder = echo_slave;
    r.enable();
    std::vector<bool> pulse;
    for (int i = 0; i < 8; ++i) {
        r.p.scan();
        pulse.push_back(r.pass_pulse());
    }
    // Scans 1–3 send sets 1–3, scan 4 applies set 3 and ends the pass, scan 5 sends set 1.
    EXPECT_EQ(pulse, (std::vector<bool>{false, false, false, true, false, false, false, true}));
    EXPECT_EQ(r.p.word(Area::D, 102), 2);
    EXPECT_EQ(r.link.sent.size(), 6u);
    EXPECT_EQ(r.p.d(2000, 2), (W{100, 101}));
}

TEST(Mbus, PassCounterWrapsAt65535) {
    Rig r;
    r.table({kRead5});
    r.p.set_word(Area::D, 102, 65535);
    r.link.responder = echo_slave;
    r.enable();
    r.p.scan(2);
    EXPECT_EQ(r.p.word(Area::D, 102), 0);
}

// Decision: M9199 pulses after a pass even when transfers failed, and failing sets are skipped
// (VB manual FNC149: "stops communication from the specific Slave and operates next").
TEST(Mbus, M9199PulsesEvenWhenEveryTransferFailed) {
    Rig r;
    r.table({{0, 1, 1, 13, 0, 4, 0}, {5, 1, 65, 13, 0, 4, 0}});  // station 0, length 65
    r.enable();
    r.p.scan();
    EXPECT_TRUE(r.pass_pulse());
    EXPECT_TRUE(r.link.sent.empty());
    r.p.scan();
    EXPECT_FALSE(r.pass_pulse());
    r.p.scan();
    EXPECT_TRUE(r.pass_pulse()) << "at most one pass per scan";
}

// The seven checks, each with its status (docs/profile-vb.md, "The cycle"); the low byte is the
// station.
struct CheckCase {
    const char* rule;
    W set;
    int status;
};

class MbusCheck : public ::testing::TestWithParam<CheckCase> {};

TEST_P(MbusCheck, FailingSetIsSkippedWithItsStatus) {
    const CheckCase& c = GetParam();
    Rig r;
    r.table({c.set, kRead5});
    r.enable();
    r.p.scan();
    EXPECT_EQ(r.status(), c.status << 8 | (c.set[0] & 0xFF)) << c.rule;
    ASSERT_EQ(r.link.sent.size(), 1u) << c.rule;
    EXPECT_EQ(r.link.sent[0].station, 5) << "the next set goes in the same scan";
}

INSTANTIATE_TEST_SUITE_P(
    Rules,
    MbusCheck,
    ::testing::Values(
        CheckCase{"1 station 0", {0, 1, 1, 13, 0, 4, 0}, 3},
        CheckCase{"1 station 248", {248, 1, 1, 13, 0, 4, 0}, 3},
        CheckCase{"1 before 2: station and command both bad", {300, 9, 1, 13, 0, 4, 0}, 3},
        CheckCase{"2 command 0", {7, 0, 1, 13, 0, 4, 0}, 2},
        CheckCase{"2 command 4", {7, 4, 1, 13, 0, 4, 0}, 2},
        CheckCase{"2 before 3: command and length bad", {7, 4, 99, 13, 0, 4, 0}, 2},
        CheckCase{"3 length 0", {7, 1, 0, 13, 0, 4, 0}, 1},
        CheckCase{"3 length 65", {7, 2, 65, 13, 0, 4, 0}, 1},
        CheckCase{"3 before 4: length and type bad", {7, 1, 65, 12, 0, 4, 0}, 1},
        CheckCase{"4 master type 12", {7, 1, 1, 12, 0, 4, 0}, 2},
        CheckCase{"4 master type 0", {7, 1, 1, 0, 0, 4, 0}, 2},
        CheckCase{"4 slave type 2", {7, 1, 1, 13, 0, 2, 0}, 2},
        CheckCase{"5 write to a read-only bit", {7, 2, 1, 3, 0, 1, 0}, 2},
        CheckCase{"5 write one to a read-only register", {7, 3, 1, 13, 0, 3, 0}, 2},
        CheckCase{"5 before 6: read-only and kinds differ", {7, 2, 1, 13, 0, 1, 0}, 2},
        CheckCase{"6 word master, bit slave", {7, 1, 1, 13, 0, 0, 0}, 4},
        CheckCase{"6 bit master, word slave", {7, 1, 1, 3, 0, 4, 0}, 4},
        CheckCase{"6 before 7: kinds differ and number bad", {7, 1, 1, 3, 9999, 4, 0}, 4},
        CheckCase{"7 D past D7999", {7, 1, 2, 13, 7999, 4, 0}, 3},
        CheckCase{"7 M in the hole", {7, 1, 1, 3, 3072, 0, 0}, 3},
        CheckCase{"7 X digit 8", {7, 1, 1, 1, 18, 0, 0}, 3},
        CheckCase{"7 Y past Y377", {7, 1, 2, 2, 377, 0, 0}, 3},
        CheckCase{"7 C value reaching C200", {7, 1, 2, 11, 199, 4, 0}, 3},
        CheckCase{"7 T value past T255", {7, 1, 1, 10, 256, 4, 0}, 3},
        CheckCase{"7 slave start + length - 1 > 32767", {7, 1, 2, 13, 0, 4, 32767}, 3},
        CheckCase{"7 slave start > 32767", {7, 1, 1, 13, 0, 4, 40000}, 3}));

// Command 3 ignores the length (VB manual FNC149, S1+3): length 0 or 99 is no error.
TEST(Mbus, WriteOneIgnoresTheLength) {
    Rig r;
    r.table({{3, 3, 99, 13, 2015, 4, 2000}});
    r.enable();
    r.p.scan();
    ASSERT_EQ(r.link.sent.size(), 1u);
    EXPECT_EQ(r.link.sent[0].quantity, 1);
    EXPECT_EQ(r.status(), 0);
}

TEST(Mbus, SpecialRegistersAndTheLastSlaveNumberAreInRange) {
    Rig r;
    r.table({{1, 1, 1, 13, 9129, 4, 32767}, {1, 1, 199, 11, 0, 4, 0}});
    r.p.set_word(Area::D, 1003, 1);
    r.p.set_word(Area::D, 1010, 2);  // C0–C1 (16-bit values)
    r.link.responder = echo_slave;
    r.enable();
    r.p.scan(3);
    EXPECT_EQ(r.status(), 0);
    EXPECT_EQ(r.link.sent.size(), 2u);
}

// Decision: S2+0 keeps a failure for at least a full pass, and goes back to 0 only at the end of
// a pass in which every transfer succeeded.
TEST(Mbus, StatusStaysUntilAPassWithoutFailure) {
    Rig r;
    r.table({kRead5, kWrite2});
    r.enable();
    r.p.scan();
    r.link.time_out();
    r.p.scan();  // set 1: status 5, set 2 sent
    EXPECT_EQ(r.status(), 5 << 8 | 5);
    r.link.reply();
    r.p.scan();  // set 2 fine, pass ends with a failure in it
    EXPECT_EQ(r.status(), 5 << 8 | 5);
    r.p.scan();
    r.link.reply(std::initializer_list<std::uint16_t>{});
    r.p.scan();
    EXPECT_EQ(r.status(), 5 << 8 | 5) << "still in the next pass";
    r.link.reply();
    r.p.scan();  // that pass had no failure
    EXPECT_EQ(r.status(), 0);
}

// FNC149 (docs/profile-vb.md, "FNC149 MBUS"): "N outside 1–255, or a table that runs past D7999:
// status 3 with station 0, nothing is sent, and the check is repeated every scan".
TEST(Mbus, BadSetCountIsStatus3StationZeroEveryScan) {
    for (const std::uint16_t n : {std::uint16_t{0}, std::uint16_t{256}}) {
        Rig r;
        r.table({kRead5});
        r.p.set_word(Area::D, 1000, n);
        r.enable();
        r.p.scan(3);
        EXPECT_EQ(r.status(), 3 << 8);
        EXPECT_TRUE(r.link.sent.empty());
        EXPECT_FALSE(r.pass_pulse());
        r.p.set_word(Area::D, 100, 0);
        r.p.scan();
        EXPECT_EQ(r.status(), 3 << 8) << "repeated at the next scan";
        r.p.set_word(Area::D, 1000, 1);
        r.p.scan();
        EXPECT_EQ(r.link.sent.size(), 1u);
    }
}

TEST(Mbus, TableRunningPastD7999IsStatus3) {
    Rig r("  - MBUS: {en: M0, s1: D7990, s2: D100}\n");
    r.p.set_word(Area::D, 7990, 2);  // 1 + 14 words from D7990: past D7999
    r.enable();
    r.p.scan();
    EXPECT_EQ(r.status(), 3 << 8);
    EXPECT_TRUE(r.link.sent.empty());
}

// FNC149 (docs/profile-vb.md, "FNC149 MBUS"): "The table, S1+0 included, is re-read at every set's
// turn."
TEST(Mbus, TableIsReadAgainAtEverySetsTurn) {
    Rig r;
    r.table({kRead5, kRead5});
    r.enable();
    r.p.scan();
    r.p.set_word(Area::D, 1008, 9);  // set 2's station, changed while set 1 is in flight
    r.link.reply({});
    r.p.scan();
    ASSERT_EQ(r.link.sent.size(), 2u);
    EXPECT_EQ(r.link.sent[1].station, 9);
    r.p.set_word(Area::D, 1000, 1);  // N shrinks: set 2 ends the pass
    r.link.reply({});
    r.p.scan();
    EXPECT_TRUE(r.pass_pulse());
}

// File registers are "read only registers" (VB manual FNC149) holding program data: the table
// may live there and a write set may send them, but no read lands there — a read set whose
// master devices touch them is skipped with status 3 (a device number error), nothing sent.
TEST(Mbus, FileRegistersHoldTheTableAndAreSentButNeverReadInto) {
    const std::string files =
        "file_registers: D1000-D1099\n"
        "init:\n"
        "  D1000: 3\n"
        "  D1001: [5, 1, 2, 13, 1050, 4, 0]\n"   // read into D1050–D1051: file registers
        "  D1008: [5, 1, 2, 13, 999, 4, 0]\n"    // D999–D1000: the last one is a file register
        "  D1015: [5, 2, 2, 13, 1090, 4, 10]\n"  // write D1090–D1091 to the slave
        "  D1090: [41, 42]\n";
    Rig r(kProgram, files);
    r.link.responder = echo_slave;
    r.enable();
    r.p.scan();
    EXPECT_EQ(r.status(), 0x0305) << "the reads are refused before anything is sent";
    ASSERT_EQ(r.link.sent.size(), 1u);
    EXPECT_EQ(r.link.sent[0].function, 16);
    EXPECT_EQ(r.link.sent[0].values[0], 41);
    EXPECT_EQ(r.link.sent[0].values[1], 42);
    r.p.scan(3);
    EXPECT_EQ(r.p.d(1050, 2), (W{0, 0})) << "no reply lands in a file register";
    EXPECT_EQ(r.p.word(Area::D, 999), 0);
    ASSERT_GE(r.link.sent.size(), 2u);
    for (const auto& q : r.link.sent)
        EXPECT_EQ(q.function, 16) << "every pass sends the write only";
    EXPECT_GE(r.p.word(Area::D, 102), 1) << "passes go on";
}

// VB manual FNC149: time-out = D9129 × 10 ms, 0 = 100 ms, read when the request is sent.
TEST(Mbus, TimeoutComesFromD9129WhenSent) {
    Rig r;
    r.table({kRead5});
    r.link.responder = echo_slave;
    r.enable();
    r.p.scan();
    EXPECT_EQ(r.link.sent.back().timeout, std::chrono::milliseconds(100));
    r.p.set_word(Area::D, special::kMbusTimeout, 50);
    r.p.scan(2);
    EXPECT_EQ(r.link.sent.back().timeout, std::chrono::milliseconds(500));
}

// VB manual FNC149: a slave that does not answer within the time-out gets status 5 ("normal
// communications but no response") and the next set goes on.
TEST(Mbus, TimeOutIsStatus5AndTheCycleGoesOn) {
    Rig r;
    r.table({kRead5, kWrite2});
    r.enable();
    r.p.scan();
    r.link.time_out();
    r.p.scan();
    EXPECT_EQ(r.status(), 5 << 8 | 5);
    ASSERT_EQ(r.link.sent.size(), 2u);
    EXPECT_EQ(r.link.sent[1].station, 2);
    EXPECT_EQ(r.p.d(2000, 2), (W{0, 0}));
}

// FNC149 reply checks (docs/profile-vb.md, "The working area and the statuses"): an exception reply
// is status 6 with its code in S2+3; S2+3 is 0 again at EN rising.
TEST(Mbus, ExceptionIsStatus6WithTheCodeInS2Plus3) {
    Rig r;
    r.table({kWrite2});
    r.enable();
    r.p.scan();
    r.link.exception(0x0B);
    r.p.scan();
    EXPECT_EQ(r.status(), 6 << 8 | 2);
    EXPECT_EQ(r.p.word(Area::D, 103), 0x0B);
    r.enable(false);
    r.p.scan();
    r.enable();
    r.p.scan();
    EXPECT_EQ(r.p.word(Area::D, 103), 0);
}

// FNC149 reply checks (docs/profile-vb.md, "The working area and the statuses"): a reply that does
// not answer the request is status 6; nothing lands.
TEST(Mbus, MalformedReplyIsStatus6AndWritesNothing) {
    Rig r;
    r.table({kRead5});
    r.enable();
    r.p.scan();
    r.link.garbage();
    r.p.scan();
    EXPECT_EQ(r.status(), 6 << 8 | 5);
    EXPECT_EQ(r.p.d(2000, 10), W(10, 0));
}

// VB manual FNC149: EN ON → OFF stops at once; the request in flight is abandoned, its late reply
// discarded, M9199 OFF; EN rising starts at set 1 again.
TEST(Mbus, EnFallingAbandonsTheRequestAndRestartsAtSet1) {
    Rig r;
    r.table({kWrite2, kRead5});
    r.link.responder = echo_slave;
    r.enable();
    r.p.scan(3);  // set 1, set 2, end of pass
    EXPECT_TRUE(r.pass_pulse());
    r.link.responder = nullptr;
    r.p.scan();  // set 1 in flight again
    r.p.scan();
    ASSERT_TRUE(r.link.busy());
    r.p.scan();
    r.enable(false);
    r.p.scan();
    EXPECT_EQ(r.link.abandoned, 1);
    EXPECT_FALSE(r.link.busy());
    EXPECT_FALSE(r.pass_pulse());
    const auto sent = r.link.sent.size();
    r.p.scan(5);
    EXPECT_EQ(r.link.sent.size(), sent) << "nothing sent while EN is OFF";
    r.enable();
    r.p.scan();
    EXPECT_EQ(r.link.sent.back().station, 2) << "set 1 again";
    EXPECT_EQ(r.p.word(Area::D, 101), 1);
}

// A request in flight when the PLC went to STOP completes while the program does not run; the
// first scan in RUN starts the table afresh and gives it up, so the link is free for set 1 (it
// was left holding that completion, and MBUS never sent again until a reload).
TEST(Mbus, StopToRunGivesUpTheRequestLeftInFlightAndStartsAtSet1) {
    Rig r;
    r.table({kWrite2, kRead5});
    r.enable();
    r.p.scan();
    ASSERT_TRUE(r.link.busy());
    r.p.plc.engine().set_running(false);
    r.p.scan(2);
    r.link.reply();  // its answer comes while the PLC is in STOP
    r.p.scan(2);
    const auto sent = r.link.sent.size();
    r.p.plc.engine().set_running(true);
    r.p.scan();
    EXPECT_EQ(r.link.abandoned, 1);
    ASSERT_EQ(r.link.sent.size(), sent + 1) << "set 1 sent again at the first scan in RUN";
    EXPECT_EQ(r.link.sent.back().station, 2);
    r.link.responder = echo_slave;
    r.link.reply();
    r.p.scan(3);
    EXPECT_EQ(r.p.d(2000, 1), W{100}) << "the passes go on: set 2 read";
}

TEST(Mbus, EnFallingWithAReadInFlightWritesNoMasterDevice) {
    Rig r;
    r.table({kRead5});
    r.enable();
    r.p.scan();
    r.enable(false);
    r.link.reply({7, 7, 7, 7, 7, 7, 7, 7, 7, 7});  // arrives, but EN went OFF first
    r.p.scan(3);
    EXPECT_EQ(r.p.d(2000, 10), W(10, 0));
}

// Without a link (a config check, a probe before the daemon opens the port) MBUS sends nothing
// and reports nothing.
TEST(Mbus, WithoutALinkNothingHappens) {
    VbPlc p(kProgram, kMbusSection);
    p.set_d(1000, {1, 5, 1, 10, 13, 2000, 4, 0});
    p.set(Area::M, 0, true);
    p.scan(5);
    EXPECT_EQ(p.word(Area::D, 100), 0);
    EXPECT_FALSE(p.bit(Area::M, special::kMbusPass));
}

// VB manual FNC149: "The MBUS instruction can be used once only in the program."
TEST(Mbus, SecondMbusIsALoadError) {
    testing::expect_config_error(
        testing::config_failure(
            [] { VbPlc p(kProgram + "  - MBUS: {en: M1, s1: D2000, s2: D200}\n", kMbusSection); }),
        "vb.yaml", 5, 5, "one MBUS only; the first is at vb.yaml:4:5");
}

// FNC149 (docs/profile-vb.md, "FNC149 MBUS"): "A program with MBUS but no mbus: section is a config
// error."
TEST(Mbus, MbusWithoutAnMbusSectionIsAConfigError) {
    testing::expect_program_error(kProgram, 5, "no mbus: section");
}

TEST(Mbus, OperandsAreDRegistersInsideD0ToD7999) {
    testing::expect_config_error(
        testing::config_failure(
            [] { VbPlc p("  - MBUS: {en: M0, s1: D1000, s2: D7998}\n", kMbusSection); }),
        "vb.yaml", 4, 35, "S2 (the working area) needs 4 registers");
    testing::expect_config_error(
        testing::config_failure(
            [] { VbPlc p("  - MBUS: {en: M0, s1: M10, s2: D100}\n", kMbusSection); }),
        "vb.yaml", 4, 24, "expected 1 word(s) in D");
}

// The `mbus:` section (docs/configuration.md): errors at their line and column.
TEST(MbusConfig, ErrorsAtTheirNode) {
    struct Case {
        std::string section;
        int line, col;
        std::string needle;
    };
    const std::vector<Case> cases{
        {"mbus: {tcp: {host: plc.local, port: 502}}\n", 2, 20, "expected an IP address"},
        {"mbus: {tcp: {port: 502}}\n", 2, 13, "'host' is required"},
        {"mbus: {transport: udp, tcp: {host: 127.0.0.1}}\n", 2, 19, "expected tcp or rtu"},
        {"mbus: {tcp: {host: 127.0.0.1, port: 70000}}\n", 2, 37, "mbus.tcp.port"},
        {"mbus: {routes: {5: \"127.0.0.1\"}}\n", 2, 20, "expected \"HOST:PORT\""},
        {"mbus: {routes: {300: \"127.0.0.1:5022\"}}\n", 2, 17, "mbus.routes station"},
        {"mbus: {transport: rtu}\n", 2, 7, "transport rtu needs rtu:"},
        {"mbus: {}\n", 2, 7, "transport tcp needs"},
        {"mbus: {transport: rtu, rtu: {device: /dev/ttyS2, baud: 1234}}\n", 2, 56, "baud"},
        {"mbus: {transport: rtu, rtu: {device: /dev/ttyS2, data_bits: 7}}\n", 2, 61,
         "mbus.rtu.data_bits: Modbus RTU carries 8-bit bytes: expected 8"},
        {"mbus: {tcp: {host: 127.0.0.1}, colour: red}\n", 2, 32, "colour"},
        {"modbus: {rtu: {device: /dev/ttyS1}}\nmbus: {transport: rtu, rtu: {device: "
         "/dev/ttyS1}}\n",
         3, 38,
         "'/dev/ttyS1' is also this PLC's modbus.rtu (a master port's serial line is "
         "its own)"},
    };
    for (const auto& c : cases) {
        SCOPED_TRACE(c.section);
        testing::expect_config_error(testing::config_failure([&] {
                                         config::parse_config(
                                             "profile: vb\n" + c.section + "program:\n" + kProgram,
                                             "vb.yaml");
                                     }),
                                     "vb.yaml", c.line, c.col, c.needle);
    }
}

// The master's line is its own among every PLC of a `plcs:` file too: no other PLC's listener
// or master port may take it, whichever of the two comes first.
TEST(MbusConfig, AMastersLineIsNoOtherPlcsListenerOrPort) {
    const std::string master =
        "profile: vb, persistence: {enabled: false}, modbus: {tcp: {port: 0}}, "
        "mbus: {transport: rtu, rtu: {device: /dev/ttyS7}}, program: [{MBUS: {en: M0, s1: D1000, "
        "s2: D100}}]";
    const std::string fbs_rtu =
        "profile: fbs, persistence: {enabled: false}, modbus: {tcp: {port: 0}, rtu: {device: "
        "/dev/ttyS7}}";
    const std::string fbs_fatek =
        "profile: fbs, persistence: {enabled: false}, modbus: {tcp: {port: 0}}, fatek: {serial: "
        "{device: /dev/ttyS7}}";
    struct Case {
        std::string first, second;
        int col;
        std::string needle;
    };
    const std::vector<Case> cases{
        {fbs_rtu, master, 122,
         "plcs[1] (b): mbus.rtu.device: '/dev/ttyS7' is also plcs[0] (a)'s modbus.rtu (a master "
         "port's serial line is its own)"},
        {master, fbs_rtu, 99,
         "plcs[1] (b): modbus.rtu.device: '/dev/ttyS7' is also plcs[0] (a)'s mbus.rtu"},
        {fbs_fatek, master, 122, "is also plcs[0] (a)'s fatek.serial (a master port's"},
        {master, master, 122, "mbus.rtu.device: '/dev/ttyS7' is also plcs[0] (a)'s mbus.rtu"},
    };
    // Under transport tcp the rtu section is unused: it takes no line.
    std::string tcp_master = master;
    tcp_master.replace(tcp_master.find("transport: rtu"), 14,
                       "transport: tcp, tcp: {host: 127.0.0.1}");
    EXPECT_EQ(
        config::parse_plcs(
            "plcs:\n  - {name: a, " + fbs_rtu + "}\n  - {name: b, " + tcp_master + "}\n", "vb.yaml")
            .size(),
        2u);
    for (const auto& c : cases) {
        SCOPED_TRACE(c.first + " / " + c.second);
        testing::expect_config_error(
            testing::config_failure([&] {
                config::parse_plcs(
                    "plcs:\n  - {name: a, " + c.first + "}\n  - {name: b, " + c.second + "}\n",
                    "vb.yaml");
            }),
            "vb.yaml", 3, c.col, c.needle);
    }
}

TEST(MbusConfig, RtuLineIsRead) {
    const auto cfg = config::parse_config(
        "profile: vb\nmbus: {transport: rtu, rtu: {device: /dev/ttyS2, baud: 19200, parity: N, "
        "stop_bits: 2}}\n",
        "vb.yaml");
    const auto m = profiles::of(cfg).master(cfg);
    ASSERT_TRUE(m);
    EXPECT_EQ(m->transport, config::MasterTransport::Rtu);
    ASSERT_TRUE(m->rtu);
    EXPECT_EQ(m->rtu->device, "/dev/ttyS2");
    EXPECT_EQ(m->rtu->baud, 19200);
    EXPECT_EQ(m->rtu->parity, 'N');
    EXPECT_EQ(m->rtu->data_bits, 8);
    EXPECT_EQ(m->rtu->stop_bits, 2);
}

TEST(MbusConfig, TcpEndpointAndRoutesAreRead) {
    const auto cfg = config::parse_config(
        "profile: vb\nmbus: {tcp: {host: 127.0.0.1, port: 5021}, routes: {5: \"127.0.0.1:5022\", "
        "6: "
        "\"[::1]:5023\"}}\n",
        "vb.yaml");
    const auto m = profiles::of(cfg).master(cfg);
    ASSERT_TRUE(m);
    EXPECT_EQ(m->tcp.host, "127.0.0.1");
    EXPECT_EQ(m->tcp.port, 5021);
    ASSERT_EQ(m->routes.size(), 2u);
    EXPECT_EQ(m->routes[0].station, 5);
    EXPECT_EQ(m->routes[0].endpoint.port, 5022);
    EXPECT_EQ(m->routes[1].endpoint.host, "::1");
}

}  // namespace
}  // namespace plcemu::profiles::vb
