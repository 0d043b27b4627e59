// The per-cause log budget that keeps remote peers from flooding the log (docs/operations.md,
// "Reliability").

#include "modbus/log_limiter.hpp"

#include <gtest/gtest.h>

#include <vector>

namespace plcemu::modbus {
namespace {

using namespace std::chrono_literals;
using Clock = LogLimiter::Clock;

TEST(LogLimiter, FirstBurstLinesOfACausePassThenTheRestAreCounted) {
    LogLimiter l(3, 10s);
    const Clock::time_point t0{1h};
    int logged = 0;
    for (int i = 0; i < 1000; ++i) logged += l.allow(LogCause::RefusedNotAllowed, t0 + 1ms * i);
    EXPECT_EQ(logged, 3);
    // Another cause has its own budget.
    EXPECT_TRUE(l.allow(LogCause::Connected, t0));
}

TEST(LogLimiter, SummaryComesOnceWhenTheWindowEndsWithTheCount) {
    LogLimiter l(2, 10s);
    const Clock::time_point t0{1h};
    for (int i = 0; i < 12; ++i) l.allow(LogCause::RefusedFull, t0);
    std::vector<std::pair<LogCause, std::uint64_t>> seen;
    auto report = [&](LogCause c, std::uint64_t n) { seen.emplace_back(c, n); };
    l.flush(t0 + 9s, report);
    EXPECT_TRUE(seen.empty()) << "no summary before the window ends";
    l.flush(t0 + 10s, report);
    ASSERT_EQ(seen.size(), 1u);
    EXPECT_EQ(seen[0].first, LogCause::RefusedFull);
    EXPECT_EQ(seen[0].second, 10u);
    l.flush(t0 + 30s, report);
    EXPECT_EQ(seen.size(), 1u) << "a summary is given once";
    // A new window gives a new burst.
    EXPECT_TRUE(l.allow(LogCause::RefusedFull, t0 + 31s));
}

TEST(LogLimiter, AQuietCauseGetsAFreshBurstAfterTheWindow) {
    LogLimiter l(1, 10s);
    const Clock::time_point t0{1h};
    EXPECT_TRUE(l.allow(LogCause::Disconnected, t0));
    EXPECT_TRUE(l.allow(LogCause::Disconnected, t0 + 11s));
    EXPECT_FALSE(l.allow(LogCause::Disconnected, t0 + 12s));
}

}  // namespace
}  // namespace plcemu::modbus
