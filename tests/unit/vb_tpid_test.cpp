// FNC92 TPID (VB manual FNC92, "Temperature PID Control"; docs/profile-vb.md, "FNC92 TPID"):
// one test per rule, with PV written by the test — the block layout, the control law solved once
// per control cycle with the integral added every scan, the time-proportioned bits, the
// sensitivity levels, the direction bit, the overshoot repression, manual mode and the bumpless
// return to auto, per-channel auto-tuning, the alarms, EN OFF, error 6705 and operand errors.
// vb_tpid_closed_loop_test.cpp runs it against the thermal plant.

#include <gtest/gtest.h>

#include <cstdint>
#include <random>
#include <string>

#include "plcemu/image/image.hpp"
#include "support/vb_plc.hpp"

namespace plcemu::profiles::vb {
namespace {

using image::Area;
using testing::VbPlc;

// The 1-based column of `key`'s value in `line`.
int column(const std::string& line, const std::string& key) {
    return static_cast<int>(line.find(" " + key + ": ") + key.size() + 4);
}

const std::string kTwo = "  - TPID: {en: M0, s1: D0, s2: D10, s3: D100, s4: D7100, n: 2}\n";

// A TPID with n = 2: SV in D0/D1, PV in D10/D11, S3 = D100 (outputs D110, D120), S4 = D7100
// (channel 1 at D7106), a 1 s control cycle (100 scans of 10 ms).
struct Rig : VbPlc {
    explicit Rig(const std::string& program = kTwo)
        : VbPlc(program) {
        set_word(Area::D, 100, 100);
        // Kp < 1 is an error on any channel: both start valid, without I and D.
        for (int c = 0; c < 2; ++c) gains(c, 100, 0, 0);
    }
    void on(bool v = true) { set(Area::M, 0, v); }
    void sv(int c, int v) { set_word(Area::D, static_cast<std::uint32_t>(c), u(v)); }
    void pv(int c, int v) { set_word(Area::D, 10 + static_cast<std::uint32_t>(c), u(v)); }
    void sv_pv(int c, int sv_value, int pv_value) {
        sv(c, sv_value);
        pv(c, pv_value);
    }
    void s3(std::uint32_t w, int v) { set_word(Area::D, 100 + w, u(v)); }
    // Kp, TI, TD, R of channel c.
    void gains(int c, int kp, int ti, int td, int r = 0) {
        const auto p = 7100 + 6 * static_cast<std::uint32_t>(c);
        set_d(p, {u(kp), u(ti), u(td), u(r)});
    }
    void alarms(int c, int limit, int deviation) {
        const auto p = 7100 + 6 * static_cast<std::uint32_t>(c);
        set_d(p + 4, {u(limit), u(deviation)});
    }
    int output(int c) { return i(word(Area::D, 110 + 10 * static_cast<std::uint32_t>(c))); }
    bool bit(std::uint32_t w, int c) { return (word(Area::D, 100 + w) >> c) & 1; }
    // Runs `scans` scans and counts those after which channel c's output bit was ON.
    int on_scans(int c, int scans) {
        int n = 0;
        for (int k = 0; k < scans; ++k) {
            scan();
            n += bit(5, c) ? 1 : 0;
        }
        return n;
    }
    int error_code() { return word(Area::D, 9067); }
    bool error_flag() { return VbPlc::bit(Area::M, 9067); }
    void clear_error() {
        set_word(Area::D, 9067, 0);
        set(Area::M, 9067, false);
    }
    static std::uint16_t u(int v) { return static_cast<std::uint16_t>(v); }
    static int i(std::uint16_t v) { return static_cast<std::int16_t>(v); }
};

// VB manual FNC92: S3+10m (m = 1…n) is channel m's analog output 0–1000 × 0.1 %, S4+6m its
// Kp (× 0.01), and the bit of S3+5 is the time-proportioned output. Kp = 100 moves the output
// 1 count per PV unit of error; the bit is ON for output/1000 of the control cycle, from its
// start.
TEST(Tpid, OutputIsKpTimesErrorAndTheBitItsShareOfTheCycle) {
    Rig r;
    r.gains(1, 200, 0, 0);
    r.sv_pv(0, 1500, 1000);
    r.sv_pv(1, 1000, 900);
    r.on();
    EXPECT_EQ(r.on_scans(0, 1), 1);
    EXPECT_EQ(r.output(0), 500);
    EXPECT_EQ(r.output(1), 200);
    // The first cycle: scans at 0…990 ms; 500/1000 of 1 s is the first 50 of them.
    EXPECT_EQ(r.on_scans(0, 49), 49);
    EXPECT_EQ(r.on_scans(0, 50), 0);
    EXPECT_EQ(r.on_scans(1, 100), 20);  // the second cycle, channel 2 at 20 %
    EXPECT_EQ(r.error_code(), 0);
}

// VB manual FNC92: the instruction "accumulates the values of difference between S1 & S2 at
// every PLC Scan Time"; the output is solved at each control-cycle boundary and stays between.
TEST(Tpid, IntegralAddsEveryScanOutputSolvedAtEachBoundary) {
    Rig r;
    r.gains(0, 100, 10, 0);  // TI = 1 s: 1 count per scan at E = 100
    r.sv_pv(0, 1500, 1400);
    r.on();
    r.scan();
    EXPECT_EQ(r.output(0), 101);  // P 100 + one scan of I
    r.scan(99);
    EXPECT_EQ(r.output(0), 101);  // not rewritten inside the cycle
    r.scan();
    EXPECT_EQ(r.output(0), 201);  // the next boundary, 1 s later
}

// Decision (docs/profile-vb.md): the integral is held to 0…1000, so a long error neither winds it
// up beyond full output nor below zero.
TEST(Tpid, IntegralIsHeldToTheOutputRange) {
    Rig r;
    r.gains(0, 100, 1, 0);  // 0.1 s: 50 counts a scan at E = 500
    r.sv_pv(0, 1500, 1000);
    r.on();
    r.scan(300);
    EXPECT_EQ(r.output(0), 1000);
    r.pv(0, 2000);
    r.scan(300);
    EXPECT_EQ(r.output(0), 0);
    r.pv(0, 1490);  // 1 count a scan: 10 + I at the next boundary
    r.scan(100);
    EXPECT_GT(r.output(0), 10);  // I counted up from 0, not from far below
    EXPECT_LE(r.output(0), 110);
}

// VB manual FNC92, TD: the derivative acts on the PV's change over the last cycle, so a PV
// moving towards SV brakes the output (heating and cooling alike).
TEST(Tpid, DerivativeBrakesOnThePvChangeOverTheCycle) {
    for (const bool forward : {false, true}) {
        SCOPED_TRACE(forward ? "forward" : "reverse");
        Rig r;
        r.s3(2, forward ? 1 : 0);
        r.gains(0, 100, 0, 100);  // TD = 1 s, Tc = 1 s
        r.sv_pv(0, 1500, forward ? 2000 : 1000);
        r.on();
        r.scan();
        EXPECT_EQ(r.output(0), 500);
        r.pv(0, forward ? 1990 : 1010);
        r.scan(100);
        EXPECT_EQ(r.output(0), 490 - 10);
    }
}

// VB manual FNC92, S3+2: bit m−1 = 0 is "Reverse" (heating: output while PV < SV), 1 is
// "Forward" (cooling: output while PV > SV), the opposite polarity of FNC88's b0.
TEST(Tpid, DirectionBitZeroHeatsOneCools) {
    Rig r;
    r.s3(2, 0b10);
    for (int c = 0; c < 2; ++c) r.sv(c, 1000);
    r.pv(0, 900);
    r.pv(1, 1200);
    r.on();
    r.scan();
    EXPECT_EQ(r.output(0), 100);
    EXPECT_EQ(r.output(1), 200);
    r.pv(0, 1200);
    r.pv(1, 900);
    r.scan(100);
    EXPECT_EQ(r.output(0), 0);
    EXPECT_EQ(r.output(1), 0);
}

// Decision (docs/profile-vb.md): the sensitivity S3+1 scales Kp by 1, 0.75, 0.5 and TI by 1,
// 1.5, 2 for fast, medium, slow; the stored S4 values stay as written.
TEST(Tpid, SensitivityScalesGainDownAndIntegralTimeUp) {
    struct Case {
        int level, first, second;
    };
    // E = 100, Kp = 100, TI = 5 s: fast 100 + 0.2/scan, medium 75 + 0.1/scan, slow 50 +
    // 0.05/scan; the second boundary comes after 101 scans of I.
    for (const Case c : {Case{0, 100, 120}, Case{1, 75, 85}, Case{2, 50, 55}}) {
        SCOPED_TRACE(c.level);
        Rig r;
        r.s3(1, c.level);
        r.gains(0, 100, 50, 0);
        r.sv_pv(0, 1500, 1400);
        r.on();
        r.scan();
        EXPECT_EQ(r.output(0), c.first);
        r.scan(100);
        EXPECT_EQ(r.output(0), c.second);
        EXPECT_EQ(r.word(Area::D, 7100), 100);
        EXPECT_EQ(r.error_code(), 0);
    }
}

// VB manual FNC92, S3+0: the control cycle in 10 ms. A new value takes effect at the next
// boundary: the cycle under way finishes at its old length.
TEST(Tpid, NewControlCycleTakesEffectAtTheNextBoundary) {
    Rig r;
    r.s3(0, 50);  // 0.5 s
    r.sv_pv(0, 1500, 1000);
    r.on();
    EXPECT_EQ(r.on_scans(0, 50), 25);
    EXPECT_EQ(r.on_scans(0, 10), 10);
    r.s3(0, 200);  // 2 s, written inside the second cycle
    EXPECT_EQ(r.on_scans(0, 40), 15);
    EXPECT_EQ(r.on_scans(0, 100), 100);  // the third cycle is 2 s: ON for its first second
    EXPECT_EQ(r.on_scans(0, 100), 0);
    EXPECT_EQ(r.on_scans(0, 1), 1);
}

// Decision (docs/profile-vb.md): S3+0 below 10 runs at 10 (100 ms) with error 6705 in D9067,
// M9067 ON and the entry in D9069.
TEST(Tpid, ControlCycleBelowTenRunsAtTenWith6705) {
    Rig r("  - MOV: {en: 1, s: 0, d: D50}\n" + kTwo);
    r.s3(0, 0);
    r.sv_pv(0, 1500, 1000);
    r.on();
    EXPECT_EQ(r.on_scans(0, 10), 5);
    EXPECT_EQ(r.on_scans(0, 10), 5);
    EXPECT_EQ(r.error_code(), 6705);
    EXPECT_TRUE(r.error_flag());
    EXPECT_EQ(r.word(Area::D, 9069), 2);
    // Raised at every scan while the value is out of range.
    r.clear_error();
    r.scan();
    EXPECT_EQ(r.error_code(), 6705);
    r.s3(0, 10);
    r.clear_error();
    r.scan(30);
    EXPECT_EQ(r.error_code(), 0);
    EXPECT_FALSE(r.error_flag());
}

// Decision (docs/profile-vb.md): out-of-range parameters run at the nearest valid value and
// raise 6705 — S3+1 outside 0–2, Kp < 1, TI, TD or R < 0.
TEST(Tpid, OutOfRangeParametersRunAtTheNearestValueWith6705) {
    struct Case {
        const char* what;
        int level, kp, ti, td, r, output;
    };
    // E = 500.
    const Case cases[] = {{"S3+1 = -1 runs fast", -1, 100, 0, 0, 0, 500},
                          {"S3+1 = 3 runs slow", 3, 100, 0, 0, 0, 250},
                          {"Kp = 0 runs at 1", 0, 0, 0, 0, 0, 5},
                          {"Kp < 0 runs at 1", 0, -300, 0, 0, 0, 5},
                          {"TI < 0 runs as no I", 0, 100, -5, 0, 0, 500},
                          {"TD < 0 runs as no D", 0, 100, 0, -100, 0, 500},
                          {"R < 0 runs as no repression", 0, 100, 10, 0, -1, 505}};
    for (const Case& c : cases) {
        SCOPED_TRACE(c.what);
        Rig r;
        r.s3(1, c.level);
        r.gains(0, c.kp, c.ti, c.td, c.r);
        r.sv_pv(0, 1500, 1000);
        r.on();
        r.scan();
        EXPECT_EQ(r.output(0), c.output);
        EXPECT_EQ(r.error_code(), 6705);
        EXPECT_TRUE(r.error_flag());
        EXPECT_EQ(r.word(Area::D, 7100), static_cast<std::uint16_t>(c.kp));  // not rewritten
    }
}

// VB manual FNC92, S4+6m+3: the overshoot repression. Decision (docs/profile-vb.md): from EN
// rising, the integral is held at 0 until |E| ≤ R; R = 0 has no such phase.
TEST(Tpid, RepressionHoldsTheIntegralUntilWithinR) {
    Rig r;
    r.gains(0, 100, 10, 0, 100);
    r.gains(1, 100, 10, 0, 0);
    for (int c = 0; c < 2; ++c) {
        r.sv_pv(c, 1500, 1000);
    }
    r.on();
    r.scan(201);
    EXPECT_EQ(r.output(0), 500);
    EXPECT_EQ(r.output(1), 1000);  // 500 + 201 scans of 5
    r.pv(0, 1420);                 // |E| = 80 ≤ R: the phase ends, I counts from 0
    r.scan(100);
    EXPECT_EQ(r.output(0), 80 + 80);
}

// Decision (docs/profile-vb.md): the start-up phase also ends at a boundary where PV has stopped
// approaching SV after approaching it, so a loop whose P-only offset exceeds R does not stay
// below SV.
TEST(Tpid, RepressionEndsWhenPvStallsAfterApproaching) {
    Rig r;
    r.gains(0, 100, 10, 0, 100);
    r.sv_pv(0, 1500, 1000);
    r.on();
    r.scan();
    EXPECT_EQ(r.output(0), 500);
    r.pv(0, 1100);
    r.scan(100);  // approached: still held
    EXPECT_EQ(r.output(0), 400);
    r.scan(100);  // stalled: the phase ends at this boundary
    EXPECT_EQ(r.output(0), 400);
    r.scan(100);
    EXPECT_EQ(r.output(0), 400 + 400);
}

// VB manual FNC92, S3+3: in manual the user writes the output (0–1000) into S3+10m and the
// instruction drives the bit from it; values outside count as 0 or 1000, and the register is
// not rewritten.
TEST(Tpid, ManualModeDrivesTheBitFromTheUsersValue) {
    Rig r;
    r.s3(3, 1);
    r.gains(0, 100, 10, 0);
    r.sv_pv(0, 1500, 1000);
    r.set_word(Area::D, 110, 300);
    r.on();
    EXPECT_EQ(r.on_scans(0, 100), 30);
    r.set_word(Area::D, 110, Rig::u(-5));
    EXPECT_EQ(r.on_scans(0, 100), 0);
    r.set_word(Area::D, 110, 1500);
    EXPECT_EQ(r.on_scans(0, 100), 100);
    EXPECT_EQ(r.output(0), 1500);
}

// Decision (docs/profile-vb.md): manual → auto is bumpless — the integral takes S3+10m − Kp'·E,
// and no start-up phase holds it at 0.
TEST(Tpid, ManualToAutoIsBumpless) {
    Rig r;
    r.s3(3, 1);
    r.gains(0, 100, 0, 0, 100);  // no I action: the bias stays as set
    r.sv_pv(0, 1500, 1300);
    r.set_word(Area::D, 110, 300);
    r.on();
    r.scan(150);
    r.s3(3, 0);
    r.scan(50);
    EXPECT_EQ(r.output(0), 300);  // 200 from P + 100 of bias
    r.pv(0, 1350);
    r.scan(100);
    EXPECT_EQ(r.output(0), 250);
}

// Decision (docs/profile-vb.md): auto → manual keeps the last automatic value in S3+10m (and so
// the same duty) until the user writes another.
TEST(Tpid, AutoToManualKeepsTheLastValue) {
    Rig r;
    r.sv_pv(0, 1500, 1000);
    r.on();
    r.scan(150);
    r.s3(3, 1);
    r.pv(0, 1400);  // no longer looked at
    r.scan(50);
    EXPECT_EQ(r.output(0), 500);
    EXPECT_EQ(r.on_scans(0, 100), 50);
}

// A PV that rises 1 count a scan while the channel's bit is ON and falls 1 while it is OFF:
// enough for the relay to oscillate between 1400 and 1500 with a period of two cycles.
int integrate(Rig& r, int pv, int scans) {
    for (int k = 0; k < scans; ++k) {
        r.scan();
        pv += r.bit(5, 0) ? 1 : -1;
        r.pv(0, pv);
    }
    return pv;
}

// VB manual FNC92, S3+4: the AT bit starts auto-tuning, stays 1 while it runs and is reset when
// it has finished. Decisions (docs/profile-vb.md): the FNC88 relay experiment with hi = 1000 and
// lo = 0 decided at cycle boundaries (the bit ON for the whole cycle when hi), the second full
// cycle measured, then Kp = round(60·Ku), TI = round(5·τ), TD = round(12.5·τ) and the integral
// at the relay's mean output. Kp < 1 is no error while the AT bit is set.
TEST(Tpid, AutoTuningRelayThenZieglerNicholsGains) {
    Rig r;
    r.s3(4, 1);
    r.gains(0, 0, 0, 0);
    r.sv_pv(0, 1500, 1400);
    r.on();
    int pv = 1400;
    for (int cycle = 0; cycle < 5; ++cycle) {
        r.scan();
        const bool hi = r.output(0) == 1000;
        EXPECT_EQ(hi, cycle % 2 == 0) << "cycle " << cycle;
        EXPECT_TRUE(r.bit(4, 0));
        EXPECT_EQ(r.bit(5, 0), hi);
        pv += hi ? 1 : -1;
        r.pv(0, pv);
        pv = integrate(r, pv, 99);
    }
    EXPECT_EQ(pv, 1500);
    r.scan();  // the third hi→lo change: τ = 2 s, τon = 1 s, a = 100
    EXPECT_FALSE(r.bit(4, 0));
    EXPECT_EQ(r.d(7100, 4), (std::vector<std::uint16_t>{764, 10, 25, 0}));
    EXPECT_EQ(r.output(0), 500);  // E = 0: the integral alone, 1000·τon/τ
    EXPECT_EQ(r.error_code(), 0);
}

// VB manual FNC92: AT runs per channel, and only in auto (a manual channel's bit waits); a
// master clearing the bit abandons the experiment and the PID takes over from the relay's
// output without touching S4.
TEST(Tpid, AutoTuningWaitsInManualAndStopsWhenItsBitIsCleared) {
    Rig r;
    r.s3(3, 1);
    r.s3(4, 1);
    r.gains(0, 55, 0, 0);
    r.sv_pv(0, 1500, 1400);
    r.set_word(Area::D, 110, 200);
    r.on();
    r.scan(150);
    EXPECT_EQ(r.output(0), 200);
    EXPECT_TRUE(r.bit(4, 0));
    r.s3(3, 0);
    r.scan(51);  // to the boundary at 2 s: the relay starts hi
    EXPECT_EQ(r.output(0), 1000);
    r.scan(50);
    r.s3(4, 0);
    r.scan();  // the integral takes 1000 − Kp'·E = 945
    r.pv(0, 1600);
    r.scan(50);  // the boundary at 3 s: −55 + 945, where the relay would give 0
    EXPECT_EQ(r.output(0), 890);
    EXPECT_FALSE(r.bit(4, 0));
    EXPECT_EQ(r.word(Area::D, 7100), 55);
}

// Decision (docs/profile-vb.md): a PV that does not move through the measured cycle (a ≤ 0)
// ends auto-tuning with the AT bit cleared, S4 unchanged and 6750 in D9067.
TEST(Tpid, AutoTuningWithAStillPvFailsWith6750) {
    Rig r;
    r.s3(4, 1);
    r.gains(0, 123, 45, 6);
    r.pv(0, 1500);
    r.on();
    // SV flips across the still PV before each boundary, so the relay switches.
    for (int cycle = 0; cycle < 6; ++cycle) {
        r.sv(0, cycle % 2 == 0 ? 1501 : 1499);
        r.scan();
        EXPECT_EQ(r.bit(4, 0), cycle < 5) << "cycle " << cycle;
        r.scan(99);
    }
    EXPECT_EQ(r.d(7100, 3), (std::vector<std::uint16_t>{123, 45, 6}));
    EXPECT_EQ(r.error_code(), 6750);
    EXPECT_TRUE(r.error_flag());
}

// VB manual FNC92, S3+6 and S3+7: the limitation alarm (heating: PV > L; cooling: PV < L) and the
// deviation alarm (PV outside SV ± Dv) are evaluated at every scan in every mode. Decision:
// strict comparisons, no hysteresis; bits n…15 are written 0.
TEST(Tpid, AlarmsEveryScanInEveryMode) {
    Rig r;
    r.s3(2, 0b10);
    r.s3(3, 0b10);  // channel 2 in manual
    r.s3(6, 0xFFFF);
    r.s3(7, 0xFFFF);
    r.alarms(0, 1550, 50);
    r.alarms(1, 100, 20);
    r.sv_pv(0, 1500, 1551);
    r.sv_pv(1, 150, 99);
    r.on();
    r.scan();
    EXPECT_EQ(r.word(Area::D, 106), 0b11);
    EXPECT_EQ(r.word(Area::D, 107), 0b11);
    r.pv(0, 1550);
    r.pv(1, 100);
    r.scan();
    EXPECT_EQ(r.word(Area::D, 106), 0);
    EXPECT_EQ(r.word(Area::D, 107), 0b10);  // 100 < 150 − 20
    r.pv(0, 1450);
    r.pv(1, 130);
    r.scan();
    EXPECT_EQ(r.word(Area::D, 107), 0);
    r.pv(0, 1449);
    r.scan();
    EXPECT_EQ(r.word(Area::D, 107), 0b01);
}

// VB manual FNC92, input contact OFF: the bits of S3+5 go OFF and the analog outputs to 0.
// Decisions (docs/profile-vb.md): the alarms too, once, so a master's later write stays; an AT
// in progress is abandoned with its bit kept; the next rise starts afresh (cycle, integral,
// start-up phase).
TEST(Tpid, EnOffClearsOutputsAndAlarmsThenStartsAfresh) {
    Rig r;
    r.s3(4, 0b10);
    r.gains(0, 100, 10, 0, 100);
    r.alarms(0, 0, 0);
    r.alarms(1, 0, 0);
    r.sv_pv(0, 1500, 1000);
    r.sv_pv(1, 500, 50);
    r.on();
    r.scan(10);
    ASSERT_NE(r.word(Area::D, 105), 0);
    ASSERT_NE(r.word(Area::D, 106), 0);
    ASSERT_EQ(r.output(1), 1000);
    r.on(false);
    r.scan();
    EXPECT_EQ(r.d(105, 3), (std::vector<std::uint16_t>{0, 0, 0}));
    EXPECT_EQ(r.output(0), 0);
    EXPECT_EQ(r.output(1), 0);
    EXPECT_EQ(r.word(Area::D, 104), 0b10);
    r.set_word(Area::D, 110, 77);
    r.scan(5);
    EXPECT_EQ(r.output(0), 77);
    r.on();
    r.scan();
    EXPECT_EQ(r.output(0), 500);   // a boundary at once, the integral held by the start-up phase
    EXPECT_EQ(r.output(1), 1000);  // the relay starts again
}

// Decision (docs/profile-vb.md): n outside 1–16 is error 6705 at every scan, and the instruction
// does not execute (nothing is written).
TEST(Tpid, NOutsideOneToSixteenIs6705AndNothingRuns) {
    for (const char* n : {"17", "0", "K-1"}) {
        SCOPED_TRACE(n);
        Rig r(std::string("  - TPID: {en: M0, s1: D0, s2: D10, s3: D100, s4: D7100, n: ") + n +
              "}\n");
        r.set_d(105, {0x1234, 0x5678});
        r.gains(0, 100, 0, 0);
        r.sv(0, 1500);
        r.on();
        r.scan();
        EXPECT_EQ(r.error_code(), 6705);
        EXPECT_TRUE(r.error_flag());
        r.clear_error();
        r.scan();
        EXPECT_EQ(r.error_code(), 6705);
        EXPECT_EQ(r.d(105, 2), (std::vector<std::uint16_t>{0x1234, 0x5678}));
        EXPECT_EQ(r.output(0), 0);
    }
}

// Decision (docs/profile-vb.md): n may be a D register, read at every scan; a change keeps the
// channels it still covers, and a return from an invalid n starts afresh.
TEST(Tpid, NFromARegister) {
    Rig r("  - TPID: {en: M0, s1: D0, s2: D10, s3: D100, s4: D7100, n: D20}\n");
    r.set_word(Area::D, 20, 2);
    for (int c = 0; c < 3; ++c) {
        r.gains(c, 100, 0, 0);
        r.sv(c, 1000);
        r.pv(c, 1000 - 100 * (c + 1));
    }
    r.on();
    r.scan();
    EXPECT_EQ(r.output(0), 100);
    EXPECT_EQ(r.output(1), 200);
    EXPECT_EQ(r.output(2), 0);
    r.set_word(Area::D, 20, 3);
    r.scan(100);
    EXPECT_EQ(r.output(2), 300);
    EXPECT_EQ(r.word(Area::D, 105), 0b111);
    r.set_word(Area::D, 20, 1);
    r.scan();
    EXPECT_EQ(r.word(Area::D, 105), 0b001);  // bits n…15 written 0
    r.set_word(Area::D, 20, 17);
    r.scan(30);
    EXPECT_EQ(r.error_code(), 6705);
    r.clear_error();
    r.set_word(Area::D, 20, 1);
    r.pv(0, 500);
    r.scan();
    EXPECT_EQ(r.output(0), 500);  // solved at once: a fresh start
    EXPECT_EQ(r.error_code(), 0);
}

// Nothing a master writes into the blocks may stop the scan or leave the outputs outside their
// range: random words in S1–S4 and n, and random EN, over many scans.
TEST(Tpid, AnyBlockContentsKeepTheOutputsInRange) {
    Rig r("  - TPID: {en: M0, s1: D0, s2: D10, s3: D100, s4: D7100, n: D20}\n");
    std::mt19937 rng(92);
    std::uniform_int_distribution<int> word(0, 0xFFFF);
    std::uniform_int_distribution<int> small(0, 40);
    for (int k = 0; k < 20000; ++k) {
        const int what = small(rng);
        if (what < 8) {
            r.set_word(Area::D, static_cast<std::uint32_t>(k % 170) + 100, Rig::u(word(rng)));
        } else if (what < 14) {
            r.set_word(Area::D, 7100 + static_cast<std::uint32_t>(k % 96), Rig::u(word(rng)));
        } else if (what < 18) {
            r.set_word(Area::D, static_cast<std::uint32_t>(k % 32), Rig::u(word(rng)));
        } else if (what < 19) {
            r.set_word(Area::D, 20, Rig::u(small(rng) - 10));
        } else if (what < 20) {
            r.on(small(rng) > 3);
        }
        r.scan();
        const int n = static_cast<std::int16_t>(r.word(Area::D, 20));
        if (n >= 1 && n <= 16 && r.VbPlc::bit(Area::M, 0)) {
            const auto mask = static_cast<std::uint16_t>(~((1u << n) - 1));
            ASSERT_EQ(r.word(Area::D, 105) & mask, 0) << "scan " << k;
        }
    }
}

// VB manual FNC92, operands: S1–S4 are D registers whose blocks (n, n, 10n + 10 and 6n words,
// n taken within 1–16) lie in D0–D7999.
TEST(Tpid, BlocksMustBeDRegistersInsideD0ToD7999) {
    struct Case {
        const char* operands;
        const char* key;
        const char* needle;
    };
    const Case cases[] = {
        {"s1: D0, s2: D10, s3: D7900, s4: D7100, n: 16", "s3",
         "S3 needs 170 registers, D7900-D8069, inside D0-D7999"},
        {"s1: D0, s2: D10, s3: D100, s4: D7950, n: 9", "s4", "S4 needs 54 registers"},
        {"s1: D7999, s2: D10, s3: D100, s4: D7100, n: 2", "s1", "S1 (SV) needs 2 registers"},
        {"s1: D0, s2: D9000, s3: D100, s4: D7100, n: 1", "s2", "inside D0-D7999"},
        {"s1: D0, s2: TN0, s3: D100, s4: D7100, n: 1", "s2", "TPID.s2: expected 1 word(s) in D"},
        // n = 40 is checked as 16, and a register n as up to 16.
        {"s1: D0, s2: D10, s3: D7900, s4: D7100, n: 40", "s3", "S3 needs 170 registers"},
        {"s1: D0, s2: D10, s3: D100, s4: D7950, n: D20", "s4", "S4 needs 96 registers"},
        {"s1: D0, s2: D10, s3: D100, s4: D7100, n: M5", "n", "TPID.n: expected 1 word(s) in D"},
        {"s1: D0, s2: D10, s3: D100, s4: D7100, n: 1, k: 2", "k", "unknown operand 'k'"},
    };
    for (const Case& c : cases) {
        const std::string line = std::string("  - TPID: {en: M0, ") + c.operands + "}\n";
        testing::expect_program_error(line, column(line, c.key), c.needle);
    }
}

// The manual allows any number of TPIDs; their S3 and S4 blocks may not overlap each other's or
// another instruction's working registers, and one TPID's S3 and S4 may not share a word.
TEST(Tpid, OverlappingBlocksAreRefusedNamingBoth) {
    using testing::config_failure;
    using testing::expect_config_error;
    const auto two = [](const std::string& second) {
        return config_failure([&] {
            VbPlc p("  - TPID: {en: M0, s1: D0, s2: D10, s3: D100, s4: D7100, n: 2}\n" + second);
        });
    };
    const std::string s3_over = "  - TPID: {en: M1, s1: D0, s2: D10, s3: D129, s4: D7200, n: 1}\n";
    expect_config_error(two(s3_over), "vb.yaml", 4, column(s3_over, "s3"),
                        "S3 D129-D148 overlaps D100-D129 of the TPID at vb.yaml:3:5");
    const std::string s4_over = "  - TPID: {en: M1, s1: D0, s2: D10, s3: D200, s4: D7111, n: 1}\n";
    expect_config_error(two(s4_over), "vb.yaml", 4, column(s4_over, "s4"),
                        "S4 D7111-D7116 overlaps D7100-D7111 of the TPID at vb.yaml:3:5");
    const std::string s3_on_s4 = "  - TPID: {en: M1, s1: D0, s2: D10, s3: D7090, s4: D300, n: 1}\n";
    expect_config_error(two(s3_on_s4), "vb.yaml", 4, column(s3_on_s4, "s3"),
                        "overlaps D7100-D7111 of the TPID");
    const std::string own = "  - TPID: {en: M0, s1: D0, s2: D10, s3: D100, s4: D115, n: 1}\n";
    testing::expect_program_error(own, column(own, "s4"),
                                  "S4 D115-D120 overlaps this TPID's S3 D100-D119");
    // Side by side is fine, and so is sharing S1 and S2.
    EXPECT_FALSE(two("  - TPID: {en: M1, s1: D0, s2: D10, s3: D130, s4: D7112, n: 1}\n").thrown);
}

}  // namespace
}  // namespace plcemu::profiles::vb
