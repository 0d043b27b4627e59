// The step rounds of the process (docs/performance.md, "Stepping many PLCs"): every stepped PLC's
// queued scans share one slice per turn of the event loop, round-robin, and what else waits on
// the loop runs between slices.

#include "daemon/step_rounds.hpp"

#include <gtest/gtest.h>

#include <asio.hpp>
#include <chrono>
#include <functional>
#include <memory>
#include <string>
#include <thread>
#include <vector>

namespace plcemu::daemon {
namespace {

using namespace std::chrono_literals;

// Runs `left` scans of `cost` each, recording its name in `log` per scan.
struct FakeStepper final : Stepper {
    FakeStepper(char n, std::string& l, int scans, std::chrono::microseconds c = 0us)
        : name(n),
          log(l),
          left(scans),
          cost(c) {}
    bool step_once() noexcept override {
        if (left == 0) return false;
        if (cost > 0us) std::this_thread::sleep_for(cost);
        log += name;
        return --left > 0;
    }
    char name;
    std::string& log;
    int left;
    std::chrono::microseconds cost;
};

TEST(StepRounds, SteppersTakeTurnsScanByScanInTheOrderTheyCame) {
    asio::io_context io;
    StepRounds rounds(io);
    std::string log;
    FakeStepper a('a', log, 3), b('b', log, 1), c('c', log, 2);
    rounds.add(a);
    rounds.add(b);
    rounds.add(c);
    rounds.add(a);  // already in: keeps its place
    io.run();
    EXPECT_EQ(log, "abcaca");
    EXPECT_EQ(rounds.size(), 0u);
}

// Ten steppers of scans of 300 µs: a slice of 1 ms runs about four scans however many PLCs step,
// so a handler posted meanwhile waits for one slice, not one per stepper.
TEST(StepRounds, OneSliceForAllSteppersBetweenOtherWork) {
    asio::io_context io;
    StepRounds rounds(io, 1ms);
    std::string log;
    std::vector<std::unique_ptr<FakeStepper>> steppers;
    for (char n = 'a'; n < 'a' + 10; ++n) {
        steppers.push_back(std::make_unique<FakeStepper>(n, log, 100, 300us));
        rounds.add(*steppers.back());
    }
    std::vector<std::size_t> scans_before_other_work;
    std::function<void()> other = [&] {
        scans_before_other_work.push_back(log.size());
        if (log.size() < 1000) asio::post(io, other);
    };
    asio::post(io, other);
    io.run();
    EXPECT_EQ(log.size(), 1000u);  // every scan ran
    ASSERT_GE(scans_before_other_work.size(), 100u);
    for (std::size_t i = 1; i < scans_before_other_work.size(); ++i) {
        // At least one scan per slice, and the slice ends once 1 ms has passed.
        const auto per_slice = scans_before_other_work[i] - scans_before_other_work[i - 1];
        EXPECT_LE(per_slice, 5u) << "slice " << i;
    }
    EXPECT_EQ(log.substr(0, 12), "abcdefghijab");
}

TEST(StepRounds, ARemovedStepperIsNotScannedAgain) {
    asio::io_context io;
    StepRounds rounds(io);
    std::string log;
    FakeStepper a('a', log, 3), b('b', log, 3);
    rounds.add(a);
    rounds.add(b);
    rounds.remove(a);
    io.run();
    EXPECT_EQ(log, "bbb");
}

TEST(StepRounds, RoundsDestroyedWithARoundPostedRunNothing) {
    asio::io_context io;
    std::string log;
    FakeStepper a('a', log, 3);
    {
        StepRounds rounds(io);
        rounds.add(a);
    }
    io.run();
    EXPECT_EQ(log, "");
}

}  // namespace
}  // namespace plcemu::daemon
