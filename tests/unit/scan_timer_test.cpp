// The one scan timer of the process (docs/architecture.md, "Threads"): every PLC's scan driver
// tells it its next deadline, and it runs each one whose deadline has come, earliest first.

#include <gtest/gtest.h>

#include <algorithm>
#include <asio.hpp>
#include <chrono>
#include <memory>
#include <string>
#include <vector>

#include "daemon/scan_timer.hpp"

namespace plcemu::daemon {
namespace {

using namespace std::chrono_literals;
using Clock = ScanTimer::Clock;

// Records when it ran, and schedules itself again `again` later that many times.
struct Driver final : Scheduled {
    Driver(ScanTimer& t, std::string n, std::vector<std::string>& l)
        : timer(t),
          name(n),
          log(l) {
        slot = timer.add(*this);
    }
    Clock::time_point due(Clock::time_point now) override {
        log.push_back(name);
        if (repeats > 0) {
            --repeats;
            timer.schedule(slot, Clock::now() + again);
        }
        return now;
    }
    ScanTimer& timer;
    std::string name;
    std::vector<std::string>& log;
    ScanTimer::Slot slot = 0;
    int repeats = 0;
    Clock::duration again{0};
};

class ScanTimerTest : public ::testing::Test {
protected:
    asio::io_context io_;
    ScanTimer timer_{io_};
    std::vector<std::string> log_;
};

TEST_F(ScanTimerTest, RunsEachDriverAtItsOwnDeadlineEarliestFirst) {
    Driver a(timer_, "a", log_);
    Driver b(timer_, "b", log_);
    const auto t0 = Clock::now();
    timer_.schedule(a.slot, t0 + 30ms);
    timer_.schedule(b.slot, t0 + 10ms);
    io_.run_for(60ms);
    EXPECT_EQ(log_, (std::vector<std::string>{"b", "a"}));
}

TEST_F(ScanTimerTest, DriversWithDifferentPeriodsKeepTheirOwnRate) {
    Driver fast(timer_, "f", log_);
    Driver slow(timer_, "s", log_);
    fast.repeats = 1000;
    fast.again = 5ms;
    slow.repeats = 1000;
    slow.again = 50ms;
    timer_.schedule(fast.slot, Clock::now());
    timer_.schedule(slow.slot, Clock::now());
    io_.run_for(120ms);
    const auto count = [&](const char* n) { return std::count(log_.begin(), log_.end(), n); };
    // 5 ms against 50 ms: ten times as many scans, give or take a loaded test machine.
    EXPECT_GE(count("f"), 5 * count("s"));
    EXPECT_GE(count("s"), 2);
}

TEST_F(ScanTimerTest, ARescheduleReplacesTheDeadlineAndCancelDropsIt) {
    Driver a(timer_, "a", log_);
    Driver b(timer_, "b", log_);
    const auto t0 = Clock::now();
    timer_.schedule(a.slot, t0 + 200ms);
    timer_.schedule(a.slot, t0 + 5ms);  // earlier: the timer wakes for it
    timer_.schedule(b.slot, t0 + 5ms);
    timer_.cancel(b.slot);  // frozen
    io_.run_for(40ms);
    EXPECT_EQ(log_, (std::vector<std::string>{"a"}));
}

TEST_F(ScanTimerTest, ARemovedDriverNeverRunsAndItsSlotServesTheNextOne) {
    std::vector<std::string> other;
    {
        Driver gone(timer_, "gone", log_);
        timer_.schedule(gone.slot, Clock::now() + 5ms);
        timer_.remove(gone.slot);  // a reload replaced the PLC
    }
    Driver next(timer_, "next", other);
    timer_.schedule(next.slot, Clock::now() + 10ms);
    io_.run_for(40ms);
    EXPECT_TRUE(log_.empty());
    EXPECT_EQ(other, (std::vector<std::string>{"next"}));
}

// Drivers due at one wake-up: each is warmed stage by stage while the ones before it run, each
// starts from the clock read the one before it ended with, and the wake-up is reported once.
struct Chained final : Scheduled {
    Chained(ScanTimer& t, int i, std::vector<std::string>& l)
        : index(i),
          log(l) {
        slot = t.add(*this);
    }
    Clock::time_point due(Clock::time_point now) override {
        log.push_back(std::to_string(index) + " due");
        began = now;
        ended = now + std::chrono::microseconds(index + 1);  // as if its scan took that long
        return ended;
    }
    void prefetch(int stage) const noexcept override {
        log.push_back(std::to_string(index) + " warm" + std::to_string(stage));
    }
    int index;
    std::vector<std::string>& log;
    ScanTimer::Slot slot = 0;
    Clock::time_point began{}, ended{};
};

TEST_F(ScanTimerTest, DriversOfOneWakeUpAreWarmedAheadAndChainTheirClockReads) {
    std::vector<std::unique_ptr<Chained>> d;
    for (int i = 0; i < 6; ++i) d.push_back(std::make_unique<Chained>(timer_, i, log_));
    const auto at = Clock::now() + 5ms;
    for (int i = 0; i < 6; ++i) {
        // Distinct deadlines a nanosecond apart fix the order; all are due at one wake-up.
        timer_.schedule(d[static_cast<std::size_t>(i)]->slot, at + std::chrono::nanoseconds(i));
    }
    io_.run_for(30ms);
    // One wake-up ran all six: each began with the clock read the one before it ended with.
    for (int i = 1; i < 6; ++i) {
        EXPECT_EQ(d[static_cast<std::size_t>(i)]->began, d[static_cast<std::size_t>(i - 1)]->ended);
    }
    // Driver 5: warmed in stages 0, 1, 2 while drivers 2, 3 and 4 ran, then run.
    std::vector<std::string> five;
    for (const auto& e : log_)
        if (e.rfind("5 ", 0) == 0) five.push_back(e);
    EXPECT_EQ(five, (std::vector<std::string>{"5 warm0", "5 warm1", "5 warm2", "5 due"}));
    const auto pos = [&](const std::string& e) { return std::find(log_.begin(), log_.end(), e); };
    EXPECT_LT(pos("2 due"), pos("5 warm1"));
    EXPECT_LT(pos("5 warm2"), pos("4 due"));
    EXPECT_LT(pos("4 due"), pos("5 due"));
}

}  // namespace
}  // namespace plcemu::daemon
