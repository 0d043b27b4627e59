// FNC88 PID (VB manual FNC88; docs/profile-vb.md, "FNC88 PID"), one rule per test: operands and
// the 25-word block, the parameter checks that stop it, the overflow codes that clamp and go on,
// sampling (accumulator, Ts ≤ scan, first execution, rerun), the velocity-form law, bumpless
// manual, the MV limit, the change alarms, EN, and relay auto-tuning with a scripted PV. The closed
// loop on the plant is vb_pid_closed_loop_test.cpp.

#include <gtest/gtest.h>

#include <chrono>
#include <cstdint>
#include <random>
#include <set>
#include <string>

#include "plcemu/config/config.hpp"
#include "plcemu/daemon/plc.hpp"
#include "profiles/vb/pid.hpp"
#include "support/config_errors.hpp"
#include "support/vb_rig.hpp"

namespace plcemu::profiles::vb {
namespace {

using namespace std::chrono_literals;
using namespace pid;

constexpr std::uint32_t kSv = 100, kPv = 101, kMv = 102, kS3 = 200;
constexpr std::uint32_t kErrorCode = 9067, kErrorEntry = 9069, kErrorRelay = 9067;

const std::string kEntry = "  - PID: {en: M0, s1: D100, s2: D101, s3: D200, d: D102}\n";

/// One PID on D100 (SV), D101 (PV), D200… (S3), D102 (MV), enabled by M0.
struct Loop : testing::VbRig {
    explicit Loop(engine::Duration dt = 10ms)
        : VbRig(kEntry, dt) {
        set_m(0, true);
    }
    void param(std::uint32_t offset, int v) { set(kS3 + offset, v); }
    int param(std::uint32_t offset) { return sd(kS3 + offset); }
    /// A valid block: Ts, S3+1, Kp, TI, TD; α = KD = 0.
    void block(int ts, int control, int kp, int ti, int td = 0) {
        param(kSampling, ts);
        param(kControl, control);
        param(kGain, kp);
        param(kIntegral, ti);
        param(kDerivative, td);
    }
    void sv(int v) { set(kSv, v); }
    /// SV and PV.
    void at(int sv_value, int pv_value) {
        sv(sv_value);
        pv(pv_value);
    }
    void pv(int v) { set(kPv, v); }
    int mv() { return sd(kMv); }
    int code() { return d(kErrorCode); }
    bool error() const { return m(kErrorRelay); }
    void clear_error() {
        d(kErrorCode) = 0;
        set_m(kErrorRelay, false);
    }
};

std::string load_error(const std::string& program) {
    const auto f = testing::config_failure([&] {
        const config::Config cfg =
            config::parse_config("profile: vb\nprogram:\n" + program, "pid_test.yaml");
        (void)daemon::build_program(cfg);
    });
    return f.thrown ? f.what : "";
}

int column_of(const std::string& line, const std::string& text) {
    return static_cast<int>(line.find(text)) + 1;
}

// ---------------------------------------------------------------------------------------------
// Operands (VB manual FNC88: S1, S2, S3 and D are D registers; S3 occupies 25 registers)

TEST(VbPid, OperandsOfTheManualFormBind) {
    EXPECT_EQ(load_error(kEntry), "");
    // The last block that fits: D7975–D7999.
    EXPECT_EQ(load_error("  - PID: {en: X0, s1: D0, s2: D1, s3: D7975, d: D9100}\n"), "");
}

TEST(VbPid, OperandsMustBeDRegisters) {
    for (const char* bad : {"M10", "K100", "TN0", "CN0", "WM0", "Y0"}) {
        const std::string line =
            "  - PID: {en: M0, s1: " + std::string(bad) + ", s2: D101, s3: D200, d: D102}\n";
        const auto f = testing::config_failure([&] {
            (void)daemon::build_program(
                config::parse_config("profile: vb\nprogram:\n" + line, "pid_test.yaml"));
        });
        testing::expect_config_error(f, "pid_test.yaml", 3, column_of(line, bad), "D");
    }
}

TEST(VbPid, ParameterBlockMustLieInD0ToD7999) {
    for (const char* bad : {"D7976", "D9000", "D9240"}) {
        const std::string line =
            "  - PID: {en: M0, s1: D100, s2: D101, s3: " + std::string(bad) + ", d: D102}\n";
        const auto f = testing::config_failure([&] {
            (void)daemon::build_program(
                config::parse_config("profile: vb\nprogram:\n" + line, "pid_test.yaml"));
        });
        testing::expect_config_error(f, "pid_test.yaml", 3, column_of(line, bad), "S3");
    }
}

// VB manual FNC88: the number of PIDs is unlimited, but each needs its own block; the error is
// at the later entry's s3 and names the earlier entry.
TEST(VbPid, OverlappingBlocksAreRefusedNamingBoth) {
    const std::string second = "  - PID: {en: M1, s1: D100, s2: D101, s3: D224, d: D103}\n";
    const auto f = testing::config_failure([&] {
        (void)daemon::build_program(
            config::parse_config("profile: vb\nprogram:\n" + kEntry + second, "pid_test.yaml"));
    });
    testing::expect_config_error(f, "pid_test.yaml", 4, column_of(second, "D224"),
                                 "D224-D248 overlaps D200-D224, owned by the PID at "
                                 "pid_test.yaml:3:5");
    // Adjacent blocks are fine.
    EXPECT_EQ(load_error(kEntry + "  - PID: {en: M1, s1: D100, s2: D101, s3: D225, d: D103}\n"),
              "");
}

// D inside its own block would overwrite a parameter at every execution (D = S3: the sampling
// time); it was accepted.
TEST(VbPid, AnOutputInsideItsOwnBlockIsRefused) {
    for (const char* d : {"D200", "D212", "D224"}) {
        const std::string line =
            "  - PID: {en: M0, s1: D100, s2: D101, s3: D200, d: " + std::string(d) + "}\n";
        const auto f = testing::config_failure([&] {
            (void)daemon::build_program(
                config::parse_config("profile: vb\nprogram:\n" + line, "pid_test.yaml"));
        });
        // At d's operand, the line's last mention of it (s3 may be the same register).
        testing::expect_config_error(f, "pid_test.yaml", 3, static_cast<int>(line.rfind(d)) + 1,
                                     std::string("PID.d: ") + d + " is S3+");
    }
    EXPECT_EQ(load_error("  - PID: {en: M0, s1: D100, s2: D101, s3: D200, d: D225}\n"), "");
}

// ---------------------------------------------------------------------------------------------
// Parameter checks: VB manual FNC88, error table, "stops operation"

TEST(VbPid, EachParameterCheckStopsWithItsCode) {
    struct Case {
        std::uint32_t offset;
        int value;
        Code code;
    };
    const Case cases[] = {
        {kSampling, 0, kBadSampling},
        {kSampling, -1, kBadSampling},
        {kFilter, 100, kBadFilter},
        {kFilter, -1, kBadFilter},
        {kGain, 0, kBadGain},
        {kIntegral, -1, kBadIntegral},
        {kDerivGain, 101, kBadDerivGain},
        {kDerivGain, -1, kBadDerivGain},
        {kDerivative, -1, kBadDerivative},
    };
    for (const Case& c : cases) {
        Loop loop;
        loop.block(100, kReverse, 100, 10);
        loop.sv(1000);
        loop.pv(500);
        loop.set(kMv, 77);
        loop.param(c.offset, c.value);
        loop.scan(50);
        EXPECT_EQ(loop.code(), c.code) << "S3+" << c.offset << " = " << c.value;
        EXPECT_TRUE(loop.error());
        EXPECT_EQ(loop.d(kErrorEntry), 1);  // the first program entry
        EXPECT_EQ(loop.mv(), 77);           // D is not touched
    }
}

// The first failing check, in the table's order, is the one stored.
TEST(VbPid, FirstFailingCheckIsStored) {
    Loop loop;
    loop.block(0, kReverse, 0, -1, -1);
    loop.param(kFilter, 100);
    loop.scan();
    EXPECT_EQ(loop.code(), kBadSampling);
    loop.param(kSampling, 100);
    loop.scan();
    EXPECT_EQ(loop.code(), kBadFilter);
    loop.param(kFilter, 0);
    loop.scan();
    EXPECT_EQ(loop.code(), kBadGain);
}

// The execution after a stop that passes every check is a first execution; before any sampling
// the loop has no memory, so nothing is computed and the first sampling comes Ts later.
TEST(VbPid, StoppedPidResumesWithAFirstExecution) {
    Loop loop;
    loop.block(0, kReverse, 100, 1);
    loop.at(1000, 900);
    loop.scan(20);
    EXPECT_EQ(loop.code(), kBadSampling);
    loop.param(kSampling, 100);
    loop.clear_error();
    loop.scan(10);  // the first execution and 90 ms
    EXPECT_EQ(loop.mv(), 0);
    loop.scan();  // 100 ms: I action, 1·(100/100)·100
    EXPECT_EQ(loop.mv(), 100);
    EXPECT_FALSE(loop.error());
}

// VB manual FNC88, program example: AT starts with Kp, TI and TD still 0; 6733, 6734 and 6736 are
// not checked while b4 = 1.
TEST(VbPid, GainsAreNotCheckedWhileAutoTuningIsAsked) {
    Loop loop;
    loop.block(2000, kReverse | kAutoTune, 0, -1, -1);
    loop.param(kTuneHigh, 500);
    loop.at(1500, 250);
    loop.scan(500);
    EXPECT_FALSE(loop.error()) << loop.code();
    EXPECT_EQ(loop.mv(), 500);
}

// ---------------------------------------------------------------------------------------------
// Sampling and first execution (VB manual FNC88)

TEST(VbPid, FirstExecutionComputesNothing) {
    Loop loop;
    loop.block(100, kReverse, 100, 1);
    loop.at(1000, 900);
    loop.set(kMv, 77);
    loop.scan();  // first execution
    EXPECT_EQ(loop.mv(), 77);
    loop.scan(9);  // 90 ms
    EXPECT_EQ(loop.mv(), 77);
    loop.scan();  // Ts: EVn−1 := EVn, so only the I term acts
    EXPECT_EQ(loop.mv(), 177);
}

// The accumulator collects the scan intervals and keeps the remainder: Ts = 25 ms with 10 ms
// scans samples after 30, 50, 80, 100 ms…, 40 times a second.
TEST(VbPid, AccumulatorKeepsTheRemainder) {
    Loop loop;
    loop.block(25, kReverse, 100, 1);  // Ts/TI = 0.25
    loop.sv(1000);
    loop.pv(600);  // EV = 400: +100 a sampling
    loop.scan();
    const int expected[] = {0, 0, 100, 100, 200, 200, 200, 300, 300, 400};
    for (int i = 0; i < 10; ++i) {
        loop.scan();
        EXPECT_EQ(loop.mv(), expected[i]) << "scan " << i + 1 << " after the first";
    }
    loop.scan(90);
    EXPECT_EQ(loop.mv(), 4000);
}

// "Sampling Time <= Scan Time": 6740, and the PID samples at every scan with Ts = the scan
// interval (10 ms here, so Ts/TI = 0.1), at equality too.
TEST(VbPid, SamplingTimeNotAboveTheScanRaises6740AndSamplesEveryScan) {
    for (int ts : {5, 10}) {
        Loop loop;
        loop.block(ts, kReverse, 100, 1);
        loop.sv(1000);
        loop.pv(900);
        loop.scan();
        EXPECT_FALSE(loop.error()) << "the first execution samples nothing";
        for (int n = 1; n <= 5; ++n) {
            loop.scan();
            EXPECT_EQ(loop.mv(), 10 * n) << "Ts = " << ts;
        }
        EXPECT_EQ(loop.code(), kSamplingTooShort);
        EXPECT_TRUE(loop.error());
    }
}

// A scan that takes no simulated time samples nothing (there is no Ts to divide by).
TEST(VbPid, AScanOfNoTimeSamplesNothing) {
    Loop loop(0ms);
    loop.block(1, kReverse, 100, 0, 10);
    loop.at(1000, 900);
    loop.scan(10);
    EXPECT_EQ(loop.mv(), 0);
    EXPECT_FALSE(loop.error());
}

// ---------------------------------------------------------------------------------------------
// The law (VB manual FNC88, "The Equations of the PID Instruction", velocity form)

// The P term acts on the change of the error, so a constant error moves nothing without I.
TEST(VbPid, ProportionalTermActsOnTheChangeOfError) {
    Loop loop;
    loop.block(100, kReverse, 200, 0);
    loop.at(1000, 900);
    loop.scan(11);
    EXPECT_EQ(loop.mv(), 0);
    loop.pv(880);  // EV 100 → 120
    loop.scan(10);
    EXPECT_EQ(loop.mv(), 40);  // 2·20
    loop.scan(50);
    EXPECT_EQ(loop.mv(), 40);
}

// Forward: MV rises when PV > SV (cooling); Reverse: when PV < SV (heating).
TEST(VbPid, ForwardRaisesMvAbovePvReverseBelow) {
    for (const bool reverse : {false, true}) {
        Loop loop;
        loop.block(100, reverse ? kReverse : 0, 100, 1);
        loop.sv(1000);
        loop.pv(1100);
        loop.scan(31);  // three samplings
        EXPECT_EQ(loop.mv(), reverse ? -300 : 300);
    }
}

// Ts/TI is a ratio of two times: Ts = 1000 ms, TI = 20 × 100 ms gives 0.5.
TEST(VbPid, IntegralTermUsesTsOverTi) {
    Loop loop;
    loop.block(1000, kReverse, 100, 20);
    loop.at(1000, 950);
    loop.run_for(1010ms);
    EXPECT_EQ(loop.mv(), 25);
    loop.run_for(1000ms);
    EXPECT_EQ(loop.mv(), 50);
}

// Dn = TD/(Ts + KD·TD)·(2·PVnf−1 − PVnf − PVnf−2) + KD·TD/(Ts + KD·TD)·Dn−1 (Reverse), and MV
// is carried as a real number: 972.5 + 3.75 stores 976, where an integer MV would give 977.
TEST(VbPid, DerivativeIsFilteredAndMvIsCarriedAsARealNumber) {
    Loop loop;
    loop.block(1000, kReverse, 100, 0, 100);  // TD = 1000 ms
    loop.param(kDerivGain, 100);              // KD·TD = 1000 ms
    loop.at(100, 0);
    loop.set(kMv, 1000);
    loop.run_for(1010ms);
    EXPECT_EQ(loop.mv(), 1000);
    loop.pv(10);  // Dn = 0.5·(−10) = −5, ΔEV = −10
    loop.run_for(1000ms);
    EXPECT_EQ(loop.mv(), 985);
    loop.pv(20);  // Dn = 0.5·0 + 0.5·(−5) = −2.5, ΔEV = −10
    loop.run_for(1000ms);
    EXPECT_EQ(loop.mv(), 973);  // 972.5, rounded half away from zero
    // Dn = 0.5·(2·20 − 20 − 10) + 0.5·(−2.5) = 3.75, ΔEV = 0
    loop.run_for(1000ms);
    EXPECT_EQ(loop.mv(), 976);
}

// Without the filter constant (KD = 0) the derivative is TD/Ts times the second difference.
TEST(VbPid, DerivativeWithoutFilter) {
    Loop loop;
    loop.block(1000, kReverse, 100, 0, 100);
    loop.at(100, 0);
    loop.set(kMv, 1000);
    loop.run_for(1010ms);
    loop.pv(10);
    loop.run_for(1000ms);
    EXPECT_EQ(loop.mv(), 980);  // Dn = −10, ΔEV = −10
}

// PVnf = α·PVnf−1 + (1 − α)·PVn.
TEST(VbPid, InputFilter) {
    Loop loop;
    loop.block(100, kReverse, 100, 0);
    loop.param(kFilter, 50);
    loop.at(0, 0);
    loop.scan(11);
    loop.pv(100);
    loop.scan(10);
    EXPECT_EQ(loop.mv(), -50);  // PVnf 50
    loop.scan(10);
    EXPECT_EQ(loop.mv(), -75);  // PVnf 75
}

// Changes to SV and to S3+3…S3+6 act at the next sampling while EN stays ON.
TEST(VbPid, ParameterChangesActAtTheNextSampling) {
    Loop loop;
    loop.block(100, kReverse, 100, 1);
    loop.at(1000, 900);
    loop.scan(11);
    EXPECT_EQ(loop.mv(), 100);
    loop.param(kIntegral, 2);  // Ts/TI 0.5
    loop.scan(10);
    EXPECT_EQ(loop.mv(), 150);
    loop.sv(1100);  // ΔEV = 100 → P 100, I 100
    loop.scan(10);
    EXPECT_EQ(loop.mv(), 350);
}

// ---------------------------------------------------------------------------------------------
// Overflow: VB manual FNC88, error table, "keeps operation"; the quantity is held to 16 bits and
// D9067 keeps the last code found in the sampling.

TEST(VbPid, PvChangeOverflow6742) {
    Loop loop;
    loop.block(100, 0, 100, 0);
    loop.at(-32768, -32768);
    loop.scan(11);
    loop.sv(32767);  // EV stays 0, so only ΔPV overflows
    loop.pv(32767);
    loop.scan(10);
    EXPECT_EQ(loop.code(), kPvChangeOverflow);
    EXPECT_EQ(loop.mv(), 0);
}

TEST(VbPid, ErrorChangeOverflow6743IsHeld) {
    Loop loop;
    loop.block(100, kReverse, 100, 0);
    loop.at(-32768, 0);
    loop.scan(11);
    loop.sv(32767);  // ΔEV = 65535, held to 32767
    loop.scan(10);
    EXPECT_EQ(loop.code(), kEvChangeOverflow);
    EXPECT_EQ(loop.mv(), 32767);
}

// 6743 then 6745 in the same sampling: D9067 is left with the later one.
TEST(VbPid, ProportionalOverflow6745IsTheLastCodeOfItsSampling) {
    Loop loop;
    loop.block(100, kReverse, 200, 0);
    loop.set(kMv, -20000);
    loop.at(-32768, 0);
    loop.scan(11);
    loop.sv(32767);
    loop.scan(10);
    EXPECT_EQ(loop.code(), kProportionalOverflow);
    EXPECT_EQ(loop.mv(), -20000 + 32767);
}

TEST(VbPid, IntegralOverflow6744) {
    Loop loop;
    loop.block(1000, kReverse, 32767, 1);  // (Kp/100)·(Ts/TI) = 3276.7
    loop.at(11, 0);
    loop.run_for(1010ms);
    EXPECT_EQ(loop.code(), kIntegralOverflow);
    EXPECT_EQ(loop.mv(), 32767);
}

TEST(VbPid, DerivativeOverflow6746) {
    Loop loop;
    loop.block(1000, kReverse, 32767, 0, 32767);  // TD/Ts = 327.67
    loop.at(0, 0);
    loop.set(kMv, 1000);
    loop.run_for(1010ms);
    loop.pv(1);  // (Kp/100)·Dn = −107367.6, held to −32768; P −327.67
    loop.run_for(1000ms);
    EXPECT_EQ(loop.code(), kDerivativeOverflow);
    EXPECT_EQ(loop.mv(), -32096);
}

TEST(VbPid, MvOverflow6747HoldsAndGoesOn) {
    Loop loop;
    loop.block(100, kReverse, 100, 1);
    loop.set(kMv, 32700);
    loop.at(1000, 900);
    loop.scan(11);
    EXPECT_EQ(loop.code(), kMvOverflow);
    EXPECT_EQ(loop.mv(), 32767);
    loop.clear_error();
    loop.scan(10);
    EXPECT_EQ(loop.code(), kMvOverflow);
    EXPECT_EQ(loop.mv(), 32767);
    // It keeps operating: the error reversed brings MV down at once.
    loop.pv(1100);
    loop.scan(10);
    EXPECT_LT(loop.mv(), 32767);
}

// Nothing a master writes may crash, hang or leave D9067 with anything but a listed code:
// random words in the whole block, SV, PV and D, EN toggling, zero TI and TD, Ts from 1 ms.
TEST(VbPid, AnythingAMasterWritesIsHandled) {
    const std::set<int> codes = {0,    6730, 6732, 6733, 6734, 6735, 6736, 6740,
                                 6742, 6743, 6744, 6745, 6746, 6747, 6750};
    std::mt19937 rng(88);
    std::uniform_int_distribution<int> word(-32768, 32767);
    std::uniform_int_distribution<int> small(-2, 120);
    std::uniform_int_distribution<int> pick(0, 31);
    Loop loop;
    loop.block(1, kReverse, 100, 0);
    for (int i = 0; i < 20000; ++i) {
        const int k = pick(rng);
        if (k < 25) {
            // Small values hit the checked ranges' edges, any value the rest.
            loop.param(static_cast<std::uint32_t>(k), (i % 3 == 0) ? small(rng) : word(rng));
        } else if (k < 28) {
            loop.set(kSv + static_cast<std::uint32_t>(k - 25), word(rng));
        } else if (k == 28) {
            loop.set_m(0, !loop.m(0));
        }
        loop.scan();
        ASSERT_TRUE(codes.count(loop.code())) << loop.code() << " at scan " << i;
    }
}

// ---------------------------------------------------------------------------------------------
// Bumpless manual and the MV limit (b5)

// A D written by someone else since the last sampling becomes MVn−1.
TEST(VbPid, DWrittenByAMasterBecomesThePreviousMv) {
    Loop loop;
    loop.block(100, kReverse, 100, 1);
    loop.at(1000, 900);
    loop.scan(31);
    EXPECT_EQ(loop.mv(), 300);
    loop.set(kMv, 5000);
    loop.scan(10);
    EXPECT_EQ(loop.mv(), 5100);
}

// b5: MV held in [S3+23, S3+22] before it is stored, so the next ΔMV starts from the held value
// and the output leaves the limit as soon as the error reverses (no wind-up).
TEST(VbPid, MvLimitHoldsWithoutWindUp) {
    Loop loop;
    loop.block(100, kReverse | kMvLimitOn, 100, 1);
    loop.param(kMvUpper, 250);
    loop.param(kMvLower, 0);
    loop.at(1000, 900);
    loop.scan(101);  // ten samplings: 1000 without the limit
    EXPECT_EQ(loop.mv(), 250);
    EXPECT_FALSE(loop.error());  // the limit is not an overflow
    loop.pv(1000);
    loop.scan(10);
    EXPECT_EQ(loop.mv(), 150);  // 250 − 100 (P): a wound-up MV of 1000 would stay at 250
}

// With S3+23 > S3+22 the two are swapped for the clamp, and no code is set.
TEST(VbPid, MvLimitsGivenTheWrongWayRoundAreSwapped) {
    Loop loop;
    loop.block(100, kReverse | kMvLimitOn, 100, 1);
    loop.param(kMvUpper, 0);
    loop.param(kMvLower, 250);
    loop.at(1000, 900);
    loop.scan(101);
    EXPECT_EQ(loop.mv(), 250);
    EXPECT_FALSE(loop.error());
}

// b2 and b5 both ON: b5 (the limit) applies, S3+24 b2/b3 stay 0 and no error is set.
TEST(VbPid, MvLimitWinsOverTheMvChangeAlarm) {
    Loop loop;
    loop.block(100, kReverse | kMvAlarmOn | kMvLimitOn, 100, 1);
    loop.param(kMvUpper, 50);
    loop.param(kMvLower, -50);
    loop.set(kMv, -50);
    loop.at(1000, 900);
    loop.scan(11);  // ΔMV = +100 > 50, which the alarm would flag
    EXPECT_EQ(loop.mv(), 50);
    EXPECT_EQ(loop.param(kAlarms), 0);
    EXPECT_FALSE(loop.error());
}

// ---------------------------------------------------------------------------------------------
// Alarms (VB manual FNC88, "Process Value Changed Alarm And Output Value Changing Alarm")

TEST(VbPid, PvChangeAlarm) {
    Loop loop;
    loop.block(100, kReverse | kPvAlarmOn, 100, 0);
    loop.param(kPvRiseAlarm, 20);
    loop.param(kPvFallAlarm, 20);
    loop.at(0, 0);
    loop.scan(11);
    EXPECT_EQ(loop.param(kAlarms), 0);
    loop.pv(30);
    loop.scan(10);
    EXPECT_EQ(loop.param(kAlarms), kPvRose);
    loop.pv(0);
    loop.scan(10);
    EXPECT_EQ(loop.param(kAlarms), kPvFell);
    loop.pv(10);  // within both settings: the bit clears
    loop.scan(10);
    EXPECT_EQ(loop.param(kAlarms), 0);
}

TEST(VbPid, MvChangeAlarm) {
    Loop loop;
    loop.block(100, kReverse | kMvAlarmOn, 100, 0);
    loop.param(kMvUpper, 50);
    loop.param(kMvLower, 50);
    loop.at(0, 0);
    loop.scan(11);
    loop.pv(60);  // ΔMV = −60
    loop.scan(10);
    EXPECT_EQ(loop.param(kAlarms), kMvFell);
    loop.pv(0);  // ΔMV = +60
    loop.scan(10);
    EXPECT_EQ(loop.param(kAlarms), kMvRose);
    loop.pv(10);  // ΔMV = −10
    loop.scan(10);
    EXPECT_EQ(loop.param(kAlarms), 0);
}

// With b1, b2 and b5 OFF the block is 20 words: S3+20…S3+24 are neither read nor written.
TEST(VbPid, ShortBlockLeavesTheAlarmWordAlone) {
    Loop loop;
    loop.block(100, kReverse, 100, 0);
    loop.param(kAlarms, 0x1234);
    loop.param(kMvUpper, 10);  // would be a limit or an alarm setting with b2/b5
    loop.at(0, 0);
    loop.scan(11);
    loop.pv(-500);
    loop.scan(10);
    EXPECT_EQ(loop.mv(), 500);
    EXPECT_EQ(loop.d(kS3 + kAlarms), 0x1234);
}

// S3+24 is the instruction's: a master's write stays until the next sampling replaces it.
TEST(VbPid, AlarmWordIsReplacedAtTheNextSampling) {
    Loop loop;
    loop.block(100, kReverse | kPvAlarmOn, 100, 0);
    loop.param(kPvRiseAlarm, 20);
    loop.param(kPvFallAlarm, 20);
    loop.scan(11);
    loop.d(kS3 + kAlarms) = 0xFFFF;
    loop.scan(5);
    EXPECT_EQ(loop.d(kS3 + kAlarms), 0xFFFF);
    loop.scan(5);
    EXPECT_EQ(loop.d(kS3 + kAlarms), 0);
}

// Negative settings are compared as they stand: ΔPV = 0 > −5.
TEST(VbPid, NegativeAlarmSettingsAreComparedAsTheyStand) {
    Loop loop;
    loop.block(100, kReverse | kPvAlarmOn, 100, 0);
    loop.param(kPvRiseAlarm, -5);
    loop.param(kPvFallAlarm, 20);
    loop.scan(11);
    EXPECT_EQ(loop.param(kAlarms), kPvRose);
}

// ---------------------------------------------------------------------------------------------
// EN (VB manual FNC88: "the content value of D will be kept")

TEST(VbPid, EnOffKeepsDAndTheAlarmsAndTheRerunSamplesAtOnce) {
    Loop loop;
    loop.block(100, kReverse | kPvAlarmOn, 100, 1);
    loop.param(kPvRiseAlarm, -1);
    loop.at(1000, 900);
    loop.scan(31);
    EXPECT_EQ(loop.mv(), 300);
    EXPECT_EQ(loop.param(kAlarms), kPvRose);
    loop.set_m(0, false);
    loop.pv(0);
    loop.scan(100);
    EXPECT_EQ(loop.mv(), 300);
    EXPECT_EQ(loop.param(kAlarms), kPvRose);
    // EN ON again: the rerun samples in its own scan with the gains as they are now and the
    // loop's memory (EVn−1 = 100, PVnf−1 = 900): P 900, I 1000·0.5.
    loop.param(kIntegral, 2);
    loop.set_m(0, true);
    loop.scan();
    EXPECT_EQ(loop.mv(), 1700);
    EXPECT_EQ(loop.param(kAlarms), kPvFell);  // ΔPV −900
    // Then every Ts from there.
    loop.scan(9);
    EXPECT_EQ(loop.mv(), 1700);
    loop.scan();
    EXPECT_EQ(loop.mv(), 2200);
}

// VB manual FNC88: "When the control parameters (S1) or (S3)+3 ~ (S3)+6 of setting values are
// changed, can rerun the PID instruction for the instant response of output value (D)." Ts 2 s,
// Kp 100 %, TI 10 s, Reverse, PV 900: three samplings at SV 1000 leave D = 60; SV 1500 gives
// ΔMV = 1·(500 + 0.2·600) = 620 at the next sampling, and at once with a rerun.
TEST(VbPid, RerunGivesTheInstantResponseToANewSetValue) {
    for (const bool rerun : {false, true}) {
        SCOPED_TRACE(rerun ? "rerun" : "EN kept ON");
        Loop loop;
        loop.block(2000, kReverse, 100, 100);
        loop.at(1000, 900);
        loop.scan(1 + 3 * 200);
        ASSERT_EQ(loop.mv(), 60);
        loop.sv(1500);
        if (rerun) {
            loop.set_m(0, false);
            loop.scan();
            loop.set_m(0, true);
            loop.scan();  // the rising scan: the proportional kick and the I term, at once
            EXPECT_EQ(loop.mv(), 680);
            loop.scan(199);
            EXPECT_EQ(loop.mv(), 680);
            loop.scan();  // Ts after the rerun: I only, 0.2·600
            EXPECT_EQ(loop.mv(), 800);
        } else {
            loop.scan(199);
            EXPECT_EQ(loop.mv(), 60);
            loop.scan();
            EXPECT_EQ(loop.mv(), 680);
        }
        EXPECT_FALSE(loop.error());
    }
}

// A rerun whose Ts is not above the scan interval samples with the scan interval and 6740, as
// every sampling then does.
TEST(VbPid, RerunWithTsNotAboveTheScanRaises6740) {
    Loop loop;
    loop.block(100, kReverse, 100, 1);
    loop.at(1000, 900);
    loop.scan(11);
    ASSERT_EQ(loop.mv(), 100);
    loop.set_m(0, false);
    loop.scan();
    loop.param(kSampling, 5);
    loop.set_m(0, true);
    loop.scan();  // I: 1·(10/100)·100
    EXPECT_EQ(loop.mv(), 110);
    EXPECT_EQ(loop.code(), kSamplingTooShort);
}

// ---------------------------------------------------------------------------------------------
// Auto-tuning (VB manual FNC88, Auto-tuning Function)

// A block asking for auto-tuning: Ts 1 s, relay 500/0, Reverse, gains left at 0.
void tuning_block(Loop& loop, int control = kReverse | kAutoTune) {
    loop.block(1000, control, 0, 0, 0);
    loop.param(kTuneHigh, 500);
    loop.param(kTuneLow, 0);
    loop.sv(1000);
}

// The first execution starts the tuning and drives D with the relay at once: hi while PV is on
// the side of SV that needs output (below it for Reverse, above it for Forward).
TEST(VbPid, TuningDrivesDWithTheRelayFromTheFirstExecution) {
    for (const bool reverse : {true, false}) {
        for (const int pv : {900, 1100}) {
            Loop loop;
            tuning_block(loop, (reverse ? kReverse : 0) | kAutoTune);
            loop.pv(pv);
            loop.scan();
            const bool hi = reverse ? pv < 1000 : pv > 1000;
            EXPECT_EQ(loop.mv(), hi ? 500 : 0) << "reverse " << reverse << ", PV " << pv;
        }
    }
}

// Step 1: with S3+14 ≤ S3+15 tuning does not start: b4 := 0, 6750, and the PID runs normally.
TEST(VbPid, TuningNeedsTheHighOutputAboveTheLow) {
    Loop loop;
    loop.block(100, kReverse | kAutoTune, 100, 1);
    loop.param(kTuneHigh, 0);
    loop.param(kTuneLow, 0);
    loop.at(1000, 900);
    loop.scan();
    EXPECT_EQ(loop.code(), kTuningFault);
    EXPECT_EQ(loop.param(kControl), kReverse);
    loop.scan(10);
    EXPECT_EQ(loop.mv(), 100);  // the PID's own first sampling
}

// The same with gains the PID cannot run with: once b4 is OFF they are checked, and stop it.
TEST(VbPid, TuningThatCannotStartLeavesTheGainsToBeChecked) {
    Loop loop;
    tuning_block(loop);
    loop.param(kTuneLow, 500);
    loop.pv(900);
    loop.scan();
    EXPECT_EQ(loop.param(kControl), kReverse);
    EXPECT_EQ(loop.code(), kBadGain);
    EXPECT_EQ(loop.mv(), 0);
}

// A triangle PV of period 20 s and ±50 around SV, sampled each second. The relay (Reverse: hi
// while PV < SV) falls at 20 s, 40 s and 60 s; the second cycle, 40–60 s, gives τ = 20 s,
// τon = 9 s (hi from 51 s), a = 100. Ku = 4·500/(π·100): Kp = round(60·Ku) = 382, TI = 5·τ =
// 100, TD = 12.5·τ = 250, D = round(500·9/20) = 225.
int triangle(engine::Duration now) {
    static const int shape[20] = {0, 10,  20,  30,  40,  50,  40,  30,  20,  10,
                                  0, -10, -20, -30, -40, -50, -40, -30, -20, -10};
    const auto s = std::chrono::duration_cast<std::chrono::seconds>(now).count();
    return 1000 + shape[s % 20];
}

TEST(VbPid, TuningMeasuresTheSecondRelayCycleAndWritesZieglerNicholsGains) {
    Loop loop;
    tuning_block(loop, kReverse | kAutoTune | kMvLimitOn);
    loop.param(kMvUpper, 100);  // the limit does not apply to the relay
    while (loop.now() < 60s) {
        const engine::Duration at = loop.now();
        loop.pv(triangle(at));
        loop.scan();
        // The relay decided at the last whole second, on the PV of that second.
        ASSERT_EQ(loop.mv(), triangle(at) < 1000 ? 500 : 0) << loop.seconds();
        ASSERT_TRUE(loop.param(kControl) & kAutoTune) << loop.seconds();
    }
    loop.pv(triangle(loop.now()));
    loop.scan();  // 60 s: the third hi→lo change
    EXPECT_EQ(loop.param(kControl), kReverse | kMvLimitOn);
    EXPECT_EQ(loop.param(kGain), 382);
    EXPECT_EQ(loop.param(kIntegral), 100);
    EXPECT_EQ(loop.param(kDerivative), 250);
    EXPECT_EQ(loop.mv(), 225);
    EXPECT_FALSE(loop.error());
}

// Step 5: a ≤ 0 (PV did not move: here SV moved across a frozen PV) → b4 := 0, gains unchanged,
// 6750.
TEST(VbPid, TuningWithoutAPvSwingFailsWith6750) {
    Loop loop;
    tuning_block(loop);
    loop.param(kGain, 50);
    loop.param(kIntegral, 7);
    loop.param(kDerivative, 3);
    loop.pv(1000);
    for (int s = 0; s < 40 && (loop.param(kControl) & kAutoTune); ++s) {
        loop.sv(s % 10 < 5 ? 1100 : 900);
        loop.run_for(1s);
    }
    EXPECT_EQ(loop.param(kControl), kReverse);
    EXPECT_EQ(loop.code(), kTuningFault);
    EXPECT_EQ(loop.param(kGain), 50);
    EXPECT_EQ(loop.param(kIntegral), 7);
    EXPECT_EQ(loop.param(kDerivative), 3);
}

// Step 6: clearing b4 aborts; the PID goes on from the current D with its parameters.
TEST(VbPid, ClearingB4AbortsTuning) {
    Loop loop;
    tuning_block(loop);
    loop.param(kGain, 100);
    while (loop.now() < 35500ms) {
        loop.pv(triangle(loop.now()));
        loop.scan();
    }
    EXPECT_EQ(loop.mv(), 500);  // hi since 31 s
    loop.param(kControl, kReverse);
    loop.pv(1000);
    loop.run_for(500ms);  // 36 s: EVn−1 := EVn, P only: nothing moves
    loop.scan();
    EXPECT_EQ(loop.mv(), 500);
    loop.pv(990);
    loop.run_for(1s);
    EXPECT_EQ(loop.mv(), 510);
    EXPECT_EQ(loop.param(kGain), 100);
    EXPECT_FALSE(loop.error());
}

// EN OFF abandons the tuning but leaves b4 ON: the next rise starts it again, the relay at once.
TEST(VbPid, EnOffAbandonsTuningKeepingB4) {
    Loop loop;
    tuning_block(loop);
    loop.pv(900);
    loop.run_for(5s);
    EXPECT_EQ(loop.mv(), 500);
    loop.set_m(0, false);
    loop.scan(10);
    EXPECT_TRUE(loop.param(kControl) & kAutoTune);
    EXPECT_EQ(loop.mv(), 500);
    loop.pv(1100);
    loop.set_m(0, true);
    loop.scan();
    EXPECT_EQ(loop.mv(), 0);
    EXPECT_TRUE(loop.param(kControl) & kAutoTune);
}

// A stopping error abandons the tuning too (b4 stays), and the next good execution restarts it.
TEST(VbPid, StoppingErrorAbandonsTuningKeepingB4) {
    Loop loop;
    tuning_block(loop);
    loop.pv(900);
    loop.run_for(3s);
    loop.param(kSampling, 0);
    loop.scan();
    EXPECT_EQ(loop.code(), kBadSampling);
    EXPECT_TRUE(loop.param(kControl) & kAutoTune);
    loop.param(kSampling, 1000);
    loop.pv(1100);
    loop.scan();
    EXPECT_EQ(loop.mv(), 0);
}

}  // namespace
}  // namespace plcemu::profiles::vb
