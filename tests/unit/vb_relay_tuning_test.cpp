// The relay auto-tuning experiment shared by the VB FNC88 PID and FNC92 TPID (VB manual FNC88,
// "Auto-tuning Function"; docs/profile-vb.md, "Auto-tuning").

#include <gtest/gtest.h>

#include <chrono>
#include <numbers>

#include "profiles/vb/relay_tuning.hpp"

namespace plcemu::profiles::vb {
namespace {

using std::chrono::seconds;
using State = RelayExperiment::State;

// VB FNC88 auto-tuning step 3: the first complete cycle is thrown away, the second is measured
// from its hi→lo change to the next; τon is the part of it spent hi, a the PV's peak to peak
// over its observations, both ends included.
TEST(RelayExperiment, MeasuresTheSecondFullCycle) {
    RelayExperiment r;
    r.start(seconds(0));
    struct Step {
        int t;
        double pv;
        bool demand;
    };
    // hi from the start; falls at 10 s (cycle 1 opens), 20 s (cycle 2 opens), 32 s (closes).
    const Step steps[] = {{0, 20, true},   {5, 90, true},   {10, 151, false}, {12, 170, false},
                          {15, 149, true}, {18, 140, true}, {20, 152, false}, {23, 175, false},
                          {26, 148, true}, {29, 120, true}, {32, 151, false}};
    for (const Step& s : steps) {
        r.observe(s.pv);
        const State st = r.decide(seconds(s.t), s.demand);
        EXPECT_EQ(r.high(), s.demand);
        EXPECT_EQ(st, s.t == 32 ? State::Measured : State::Running) << "at " << s.t << " s";
    }
    EXPECT_DOUBLE_EQ(r.cycle().tau, 12.0);
    EXPECT_DOUBLE_EQ(r.cycle().tau_on, 6.0);
    // 152 at 20 s … 175 at 23 s and 120 at 29 s: the 170 of cycle 1 does not count.
    EXPECT_DOUBLE_EQ(r.cycle().a, 55.0);
    EXPECT_DOUBLE_EQ(r.cycle().duty(), 0.5);
}

// The mean relay output both instructions start from after tuning; an empty cycle has none.
TEST(RelayCycle, DutyIsTheHighPartOfThePeriod) {
    EXPECT_DOUBLE_EQ((RelayCycle{20.0, 5.0, 1.0}).duty(), 0.25);
    EXPECT_DOUBLE_EQ((RelayCycle{0.0, 0.0, 1.0}).duty(), 0.0);
}

// Starting with PV above SV (relay lo): the first lo→hi change opens nothing.
TEST(RelayExperiment, StartingLowCountsOnlyFalls) {
    RelayExperiment r;
    r.start(seconds(0));
    int t = 0;
    State last = State::Running;
    for (bool demand : {false, true, false, true, false, true, false}) {
        r.observe(demand ? 100.0 : 110.0);
        last = r.decide(seconds(t), demand);
        t += 5;
    }
    EXPECT_EQ(last, State::Measured);
    EXPECT_DOUBLE_EQ(r.cycle().tau, 10.0);
    EXPECT_DOUBLE_EQ(r.cycle().tau_on, 5.0);
    EXPECT_DOUBLE_EQ(r.cycle().a, 10.0);
}

// Ziegler–Nichols ultimate cycle: Kp = 0.6·Ku in %, TI = 0.5·Pu in 100 ms, TD = 0.125·Pu in
// 10 ms, with Ku = 4·(hi − lo)/(π·a).
TEST(ZieglerNichols, GivesTheVbUnits) {
    const RelayCycle c{26.0, 13.0, 4000.0 / std::numbers::pi};  // Ku = 1 for a span of 1000
    const TunedGains g = ziegler_nichols(1000.0, c);
    EXPECT_EQ(g.kp, 60);
    EXPECT_EQ(g.ti, 130);
    EXPECT_EQ(g.td, 325);
}

TEST(ZieglerNichols, HoldsEachRegisterToItsRange) {
    const TunedGains big = ziegler_nichols(1000.0, {9000.0, 10.0, 0.001});
    EXPECT_EQ(big.kp, 32767);
    EXPECT_EQ(big.ti, 32767);
    EXPECT_EQ(big.td, 32767);
    const TunedGains small = ziegler_nichols(1.0, {0.01, 0.0, 1e6});
    EXPECT_EQ(small.kp, 1);
    EXPECT_EQ(small.ti, 1);
    EXPECT_EQ(small.td, 0);
}

}  // namespace
}  // namespace plcemu::profiles::vb
