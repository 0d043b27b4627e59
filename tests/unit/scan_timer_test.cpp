// The one scan timer of the process (docs/architecture.md, "Threads"): every PLC's scan driver
// tells it its next deadline, and it runs each one whose deadline has come, earliest first.

#include <gtest/gtest.h>

#include <algorithm>
#include <asio.hpp>
#include <chrono>
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
    void due() override {
        log.push_back(name);
        if (repeats > 0) {
            --repeats;
            timer.schedule(slot, Clock::now() + again);
        }
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

}  // namespace
}  // namespace plcemu::daemon
