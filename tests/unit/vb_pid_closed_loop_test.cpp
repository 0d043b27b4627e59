// FNC88 PID closing the loop on the default plant (K 400 °C, τ 120 s, θ 5 s, 25 °C, no noise,
// 10 ms scans), PV read as round(T·10), the heater driven by D102 with 500 = full power: relay
// auto-tuning from cold, the tuned step with and without the MV limit, the operation errors and
// the change alarms on a running loop (VB manual FNC88; docs/profile-vb.md, "FNC88 PID", whose
// figures these are).

#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cstdint>
#include <cstdlib>
#include <iostream>
#include <optional>

#include "profiles/vb/pid.hpp"
#include "support/vb_rig.hpp"

namespace plcemu::profiles::vb {
namespace {

using namespace std::chrono_literals;
using namespace pid;

constexpr std::uint32_t kSv = 100, kPv = 101, kMv = 102, kS3 = 200, kDrive = 300;
constexpr std::uint32_t kErrorCode = 9067, kErrorRelay = 9067;
constexpr int kFullScale = 500;

/// The VB manual's PID example on the plant: SV 150.0 °C, Ts 2 s, α = KD = 0, relay 500/0,
/// MV limit 0–500.
struct Plant : testing::VbRig {
    explicit Plant(int control)
        : VbRig("  - PID: {en: M0, s1: D100, s2: D101, s3: D200, d: D102}\n") {
        close_loop(kPv, kMv, kFullScale, kDrive);
        set(kSv, 1500);
        param(kSampling, 2000);
        param(kControl, control);
        param(kTuneHigh, 500);
        param(kTuneLow, 0);
        param(kMvUpper, 500);
        param(kMvLower, 0);
        set_m(0, true);
    }
    void param(std::uint32_t offset, int v) { set(kS3 + offset, v); }
    int param(std::uint32_t offset) { return sd(kS3 + offset); }
    int pv() { return sd(kPv); }
    int mv() { return sd(kMv); }
    bool error() const { return m(kErrorRelay); }
};

/// A step response as the PLC reads it: peak, when PV first reached a level, and the last time
/// it was outside a band.
struct Response {
    int peak = -32768;
    int peak_mv = -32768;
    std::optional<double> reached;  // first reading ≥ `level`
    double outside = 0;             // last reading outside the band
    int low = 32767;                // over the window
    int high = -32768;
    bool error = false;  // M9067 seen
};

/// Runs `plant` until `end` s, recording from now on; band 1500 ± `band`, window [from, end].
Response run(Plant& plant, double end, int level, int band, double from) {
    Response r;
    while (plant.seconds() < end) {
        plant.scan();
        const int pv = plant.pv();
        r.peak = std::max(r.peak, pv);
        r.peak_mv = std::max(r.peak_mv, plant.mv());
        if (!r.reached && pv >= level) r.reached = plant.seconds();
        if (std::abs(pv - 1500) > band) r.outside = plant.seconds();
        if (plant.seconds() >= from) {
            r.low = std::min(r.low, pv);
            r.high = std::max(r.high, pv);
        }
        r.error = r.error || plant.error();
    }
    return r;
}

// Auto-tuning from cold (D201 = 0031h: Reverse, AT, limit; Kp = TI = TD = 0).
TEST(VbPidClosedLoop, AutoTuneFromCold) {
    Plant plant(kReverse | kAutoTune | kMvLimitOn);
    int peak = 0;
    bool error = false;
    while ((plant.param(kControl) & kAutoTune) && plant.seconds() < 600) {
        plant.scan();
        peak = std::max(peak, plant.pv());
        error = error || plant.error();
    }
    const double done = plant.seconds();
    const int kp = plant.param(kGain), ti = plant.param(kIntegral), td = plant.param(kDerivative);
    const int after = plant.mv();
    std::cout << "[ figures  ] AT done at " << done << " s: Kp " << kp << ", TI " << ti << ", TD "
              << td << ", D102 " << after << ", peak during AT " << peak / 10.0 << " °C\n";
    EXPECT_NEAR(done, 100, 10);
    EXPECT_NEAR(kp, 223, 223 * 0.15);
    EXPECT_NEAR(ti, 130, 130 * 0.20);
    EXPECT_NEAR(td, 325, 325 * 0.20);
    EXPECT_NEAR(after, 154, 10);
    EXPECT_NEAR(peak, 1624, 15);
    const Response r = run(plant, 1800, 0, 20, 1200);
    std::cout << "[ figures  ] after AT: outside 148.0–152.0 °C last at " << r.outside - done
              << " s after AT; minutes 20–30 " << r.low / 10.0 << "–" << r.high / 10.0 << " °C\n";
    EXPECT_LE(r.outside - done, 60);
    EXPECT_GE(r.low, 1497);
    EXPECT_LE(r.high, 1503);
    EXPECT_FALSE(error || r.error);
}

// The step 25 → 150 °C with the tuned gains (D201 = 0021h, Kp 223, TI 130, TD 325, D102 = 0).
TEST(VbPidClosedLoop, TunedStepWithTheMvLimit) {
    Plant plant(kReverse | kMvLimitOn);
    plant.param(kGain, 223);
    plant.param(kIntegral, 130);
    plant.param(kDerivative, 325);
    const Response r = run(plant, 1800, 1490, 20, 1200);
    std::cout << "[ figures  ] tuned step: 149.0 °C at " << r.reached.value_or(-1) << " s, peak "
              << r.peak / 10.0 << " °C, outside 148.0–152.0 °C last at " << r.outside
              << " s, minutes 20–30 " << r.low / 10.0 << "–" << r.high / 10.0 << " °C\n";
    ASSERT_TRUE(r.reached);
    EXPECT_NEAR(*r.reached, 54, 5);
    EXPECT_LE(r.peak, 1560);
    EXPECT_LE(r.outside, 100);
    EXPECT_GE(r.low, 1495);
    EXPECT_LE(r.high, 1505);
    EXPECT_FALSE(r.error);
}

// The same without b5 (D201 = 0001h): the velocity form winds up far past full power, and the
// PV overshoots by tens of degrees. The limit is what makes the step behave.
TEST(VbPidClosedLoop, TunedStepWithoutTheLimitWindsUp) {
    Plant plant(kReverse);
    plant.param(kGain, 223);
    plant.param(kIntegral, 130);
    plant.param(kDerivative, 325);
    const Response r = run(plant, 1800, 1490, 20, 1200);
    std::cout << "[ figures  ] without b5: D102 up to " << r.peak_mv << ", peak " << r.peak / 10.0
              << " °C\n";
    EXPECT_GT(r.peak_mv, 2000);  // ref. 3306
    EXPECT_NEAR(r.peak, 2151, 30);
}

// Operation errors on the running loop: a stopping code freezes D102 and the PID resumes once
// the block is right and the error cleared; Ts below the scan samples at every scan.
TEST(VbPidClosedLoop, OperationErrors) {
    Plant plant(kReverse | kMvLimitOn);
    plant.param(kGain, 223);
    plant.param(kIntegral, 130);
    plant.param(kDerivative, 325);
    plant.run_for(100s);  // near SV, D102 inside the limit and moving
    EXPECT_FALSE(plant.error());
    plant.param(kSampling, 0);
    plant.scan();
    EXPECT_TRUE(plant.error());
    EXPECT_EQ(plant.d(kErrorCode), kBadSampling);
    const int frozen = plant.mv();
    plant.run_for(10s);
    EXPECT_EQ(plant.mv(), frozen);

    plant.param(kSampling, 2000);
    plant.d(kErrorCode) = 0;
    plant.set_m(kErrorRelay, false);
    plant.run_for(10s);
    EXPECT_FALSE(plant.error());
    EXPECT_NE(plant.mv(), frozen);

    plant.param(kFilter, 100);
    plant.scan();
    EXPECT_EQ(plant.d(kErrorCode), kBadFilter);
    plant.param(kFilter, 0);
    plant.param(kDerivGain, 101);
    plant.scan();
    EXPECT_EQ(plant.d(kErrorCode), kBadDerivGain);
    plant.param(kDerivGain, 0);

    // In auto-tuning Kp = 0 is not an error.
    plant.param(kSampling, 2000);
    plant.param(kControl, kReverse | kAutoTune);
    plant.param(kGain, 0);
    plant.d(kErrorCode) = 0;
    plant.set_m(kErrorRelay, false);
    plant.run_for(10s);
    EXPECT_FALSE(plant.error()) << plant.d(kErrorCode);
}

// Ts = 5 ms, below the 10 ms scan: 6740, and D102 moves at every scan (from cold, without the
// limit, where the I term alone moves it by about 2 counts a scan).
TEST(VbPidClosedLoop, SamplingTimeBelowTheScan) {
    Plant plant(kReverse);
    plant.param(kGain, 223);
    plant.param(kIntegral, 130);
    plant.param(kDerivative, 325);
    plant.param(kSampling, 5);
    plant.scan();  // the first execution
    int changes = 0;
    for (int i = 0; i < 100; ++i) {
        const int before = plant.mv();
        plant.scan();
        changes += plant.mv() != before ? 1 : 0;
    }
    EXPECT_EQ(plant.d(kErrorCode), kSamplingTooShort);
    EXPECT_EQ(changes, 100);
}

// PV change alarm during the tuned step (D201 = 0023h, D220 = D221 = 20): on while PV rises by
// more than 2.0 °C per 2 s sampling, off at steady state; the MV change alarm (b2, b5 OFF,
// D222 = 50) at the first samplings.
TEST(VbPidClosedLoop, ChangeAlarms) {
    Plant plant(kReverse | kPvAlarmOn | kMvLimitOn);
    plant.param(kGain, 223);
    plant.param(kIntegral, 130);
    plant.param(kDerivative, 325);
    plant.param(kPvRiseAlarm, 20);
    plant.param(kPvFallAlarm, 20);
    bool rose = false;
    while (plant.seconds() < 120) {
        plant.scan();
        rose = rose || (plant.param(kAlarms) & kPvRose) != 0;
    }
    EXPECT_TRUE(rose);
    plant.run_for(1200s);
    EXPECT_EQ(plant.param(kAlarms), 0);

    Plant mv(kReverse | kMvAlarmOn);
    mv.param(kGain, 223);
    mv.param(kIntegral, 130);
    mv.param(kDerivative, 325);
    mv.param(kMvUpper, 50);
    mv.run_for(2010ms);  // the first sampling
    EXPECT_TRUE(mv.param(kAlarms) & kMvRose) << mv.param(kAlarms);
}

}  // namespace
}  // namespace plcemu::profiles::vb
