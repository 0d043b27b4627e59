// The scan driver's deadline arithmetic (docs/architecture.md, "Threads";
// docs/simulator-and-plant.md, "Simulator-control unit"): a pure function of the `now` it is given,
// so every case runs on made-up instants, no clock read.

#include <gtest/gtest.h>

#include <chrono>
#include <cstdint>
#include <vector>

#include "daemon/scan_schedule.hpp"

namespace plcemu::daemon {
namespace {

using namespace std::chrono_literals;
using TimePoint = ScanSchedule::TimePoint;

// An arbitrary start instant, far from the clock's epoch.
const TimePoint t0 = TimePoint{} + 1000s;

// Runs every scan due at `now` as the driver does (one after another, each at its simulated time)
// and returns their simulated times.
std::vector<engine::Duration> run_due(ScanSchedule& s, TimePoint now) {
    std::vector<engine::Duration> ran;
    for (auto d = s.due(now); d.scans > 0; d = s.due(now)) {
        ran.push_back(s.next_sim());
        s.ran();
    }
    return ran;
}

TEST(ScanSchedule, OnTimeScansAreDueOnePeriodApart) {
    ScanSchedule s(10ms, 1.0);
    s.start(0ms, t0);
    EXPECT_EQ(s.due(t0 - 1ns).scans, 0u);
    EXPECT_EQ(s.due(t0 - 1ns).next_deadline, t0);
    EXPECT_EQ(s.due(t0).scans, 1u);
    EXPECT_EQ(s.due(t0).next_deadline, t0);
    s.ran();
    EXPECT_EQ(s.next_sim(), 10ms);
    // Not due again before its deadline, then at it to the nanosecond.
    EXPECT_EQ(s.due(t0 + 9ms).scans, 0u);
    EXPECT_EQ(s.due(t0 + 9ms).next_deadline, t0 + 10ms);
    EXPECT_EQ(s.due(t0 + 10ms).scans, 1u);
    s.ran();
    EXPECT_EQ(s.due(t0 + 20ms - 1ns).scans, 0u);
    EXPECT_EQ(s.due(t0 + 20ms - 1ns).next_deadline, t0 + 20ms);
}

TEST(ScanSchedule, ARestartGoesOnFromTheEnginesTime) {
    ScanSchedule s(10ms, 1.0);
    s.start(250ms, t0);  // a reload: the engine had scanned up to 240 ms
    EXPECT_EQ(s.next_sim(), 250ms);
    EXPECT_EQ(s.due(t0).next_deadline, t0);
    s.ran();
    EXPECT_EQ(s.due(t0).next_deadline, t0 + 10ms);
}

// A late scan runs at its own simulated time (the engine's dt stays the period); the deadlines
// after it stay where they were: the loop catches up rather than shifting the schedule.
TEST(ScanSchedule, ALateScanKeepsTheDeadlinesAfterIt) {
    ScanSchedule s(10ms, 1.0);
    s.start(0ms, t0);
    s.ran();
    const auto d = s.due(t0 + 13ms);  // 3 ms late
    EXPECT_EQ(d.scans, 1u);
    EXPECT_EQ(d.next_deadline, t0 + 10ms);  // the lateness is now - next_deadline
    EXPECT_EQ(run_due(s, t0 + 13ms), (std::vector<engine::Duration>{10ms}));
    EXPECT_EQ(s.due(t0 + 13ms).next_deadline, t0 + 20ms);
}

// Many periods missed (a loop held up for 250 ms): every one of them is due, and they run back
// to back at consecutive simulated times, so simulated time loses nothing while the loop is
// less than a second behind.
TEST(ScanSchedule, ManyMissedPeriodsAreAllDueAndCaughtUp) {
    ScanSchedule s(10ms, 1.0);
    s.start(0ms, t0);
    EXPECT_EQ(s.due(t0 + 250ms).scans, 26u);  // 0, 10, ..., 250 ms
    EXPECT_EQ(s.due(t0 + 250ms - 1ns).scans, 25u);
    const auto ran = run_due(s, t0 + 250ms);
    ASSERT_EQ(ran.size(), 26u);
    for (std::size_t i = 0; i < ran.size(); ++i) EXPECT_EQ(ran[i], 10ms * i);
    EXPECT_FALSE(s.skip_ahead(t0 + 250ms));
    EXPECT_EQ(s.due(t0 + 250ms).next_deadline, t0 + 260ms);
}

// More than a second behind (a host too slow for the time scale): the missed scans are given
// up; the next runs now at the simulated time it had, and the deadlines go on from now.
TEST(ScanSchedule, MoreThanASecondBehindSkipsAheadWithoutAJumpInSimulatedTime) {
    ScanSchedule s(10ms, 1.0);
    s.start(0ms, t0);
    // Only 2 ms of the scans could run in the driver's slice; it is 5 s behind.
    s.ran();
    s.ran();
    const TimePoint now = t0 + 5s;
    EXPECT_EQ(s.due(now).scans, 499u);
    EXPECT_FALSE(s.skip_ahead(t0 + 20ms + 1s));  // exactly one second behind: not yet
    EXPECT_TRUE(s.skip_ahead(now));
    EXPECT_EQ(s.next_sim(), 20ms);
    EXPECT_EQ(s.due(now).scans, 1u);
    EXPECT_EQ(s.due(now).next_deadline, now);
    s.ran();
    EXPECT_EQ(s.due(now).next_deadline, now + 10ms);
    EXPECT_FALSE(s.skip_ahead(now));
}

// Time scale 2.0 halves the real period, 0.5 doubles it: one real second runs 2 s or 0.5 s of
// simulated time, every scan still one period after the last.
TEST(ScanSchedule, TimeScaleDividesTheRealPeriod) {
    struct Case {
        double scale;
        std::size_t scans_in_1s;  // deadlines 0 .. 1 s inclusive
        engine::Duration next_sim;
        TimePoint next_deadline;
    };
    for (const Case& c : {Case{2.0, 201, 2010ms, t0 + 1005ms}, Case{0.5, 51, 510ms, t0 + 1020ms}}) {
        ScanSchedule s(10ms, c.scale);
        s.start(0ms, t0);
        const auto ran = run_due(s, t0 + 1s);
        ASSERT_EQ(ran.size(), c.scans_in_1s) << c.scale;
        EXPECT_EQ(ran.back(), 10ms * (ran.size() - 1)) << c.scale;
        EXPECT_EQ(s.next_sim(), c.next_sim) << c.scale;
        EXPECT_EQ(s.due(t0 + 1s).next_deadline, c.next_deadline) << c.scale;
    }
}

// A new scale applies from the instant it is set: simulated time neither jumps nor repeats, the
// next scan is due at once, and later deadlines follow the new scale.
TEST(ScanSchedule, AChangeOfScaleMidRunKeepsSimulatedTimeContinuous) {
    ScanSchedule s(10ms, 1.0);
    s.start(0ms, t0);
    auto ran = run_due(s, t0 + 95ms);  // 0..90 ms
    ASSERT_EQ(ran.size(), 10u);
    EXPECT_EQ(s.next_sim(), 100ms);
    s.set_time_scale(4.0, t0 + 95ms);
    EXPECT_EQ(s.time_scale(), 4.0);
    EXPECT_EQ(s.due(t0 + 95ms).next_deadline, t0 + 95ms);
    EXPECT_EQ(s.due(t0 + 95ms).scans, 1u);
    const auto after = run_due(s, t0 + 105ms);  // 10 ms real at 4x: 40 ms simulated, 5 scans
    EXPECT_EQ(after, (std::vector<engine::Duration>{100ms, 110ms, 120ms, 130ms, 140ms}));
    EXPECT_EQ(s.due(t0 + 105ms).next_deadline, t0 + 107500us);
    // Back to 1.0: again no jump.
    s.set_time_scale(1.0, t0 + 106ms);
    EXPECT_EQ(s.next_sim(), 150ms);
    EXPECT_EQ(s.due(t0 + 106ms).next_deadline, t0 + 106ms);
    s.ran();
    EXPECT_EQ(s.due(t0 + 106ms).next_deadline, t0 + 116ms);
}

// Frozen, nothing is due however late it gets; resumed, simulated time goes on from where it
// stopped (no catching up on the frozen stretch) and the next scan is due at once.
TEST(ScanSchedule, FreezeAndResume) {
    ScanSchedule s(10ms, 1.0);
    s.start(0ms, t0);
    run_due(s, t0 + 30ms);  // 0..30 ms
    EXPECT_TRUE(s.set_frozen(true, t0 + 31ms));
    EXPECT_FALSE(s.set_frozen(true, t0 + 32ms));  // already frozen: no change
    EXPECT_TRUE(s.frozen());
    EXPECT_EQ(s.due(t0 + 1h).scans, 0u);
    EXPECT_EQ(s.due(t0 + 1h).next_deadline, TimePoint::max());
    EXPECT_FALSE(s.skip_ahead(t0 + 31ms));
    EXPECT_TRUE(s.set_frozen(false, t0 + 1h));
    EXPECT_FALSE(s.frozen());
    EXPECT_EQ(s.next_sim(), 40ms);
    EXPECT_EQ(s.due(t0 + 1h).scans, 1u);
    EXPECT_EQ(s.due(t0 + 1h).next_deadline, t0 + 1h);
    s.ran();
    EXPECT_EQ(s.due(t0 + 1h).next_deadline, t0 + 1h + 10ms);
}

// step(n) while frozen: each queued scan runs at the next simulated time, nothing else becomes
// due, and the PLC resumes from the last step.
TEST(ScanSchedule, StepWhileFrozen) {
    ScanSchedule s(10ms, 1.0);
    s.start(0ms, t0);
    s.set_frozen(true, t0);
    s.queue_steps(3);
    EXPECT_EQ(s.pending_steps(), 3u);
    std::vector<engine::Duration> stepped;
    while (s.pending_steps() > 0) {
        stepped.push_back(s.next_sim());
        s.stepped(t0 + 5s);
        EXPECT_EQ(s.due(t0 + 5s).scans, 0u);  // still frozen
    }
    EXPECT_EQ(stepped, (std::vector<engine::Duration>{0ms, 10ms, 20ms}));
    s.set_frozen(false, t0 + 6s);
    EXPECT_EQ(s.next_sim(), 30ms);
    EXPECT_EQ(s.due(t0 + 6s).next_deadline, t0 + 6s);
}

// A step of a running PLC goes on in real time from where the step ended: the scans it took
// the place of are not caught up afterwards.
TEST(ScanSchedule, StepWhileRunningRebasesOnTheStep) {
    ScanSchedule s(10ms, 1.0);
    s.start(0ms, t0);
    s.queue_steps(1);
    s.stepped(t0 + 500ms);
    EXPECT_EQ(s.pending_steps(), 0u);
    EXPECT_EQ(s.next_sim(), 10ms);
    EXPECT_EQ(s.due(t0 + 500ms).scans, 1u);
    EXPECT_EQ(s.due(t0 + 500ms).next_deadline, t0 + 500ms);
}

TEST(ScanSchedule, QueuedStepsAreBoundedAndCancelled) {
    ScanSchedule s(10ms, 1.0);
    s.queue_steps(10);
    s.queue_steps(ScanSchedule::kMaxPendingSteps);
    EXPECT_EQ(s.pending_steps(), ScanSchedule::kMaxPendingSteps);
    s.queue_steps(UINT64_MAX);
    EXPECT_EQ(s.pending_steps(), ScanSchedule::kMaxPendingSteps);
    s.cancel_steps();
    EXPECT_EQ(s.pending_steps(), 0u);
    s.queue_steps(0);
    EXPECT_EQ(s.pending_steps(), 0u);
}

// An hours-long stall (a suspended host) counts without overflowing.
TEST(ScanSchedule, AVeryLongStallIsCountedWithinBounds) {
    ScanSchedule s(1000ms, 100000.0);
    s.start(0ms, t0);
    EXPECT_EQ(s.due(t0 + 24h).scans, ScanSchedule::kMaxDue);
    ScanSchedule slow(1ms, 1.0);
    slow.start(0ms, t0);
    EXPECT_EQ(slow.due(t0 + 1h).scans, 3'600'001u);
}

}  // namespace
}  // namespace plcemu::daemon
