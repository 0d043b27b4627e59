// The per-cause log budget that keeps remote peers from flooding the log (docs/operations.md,
// "Reliability").

#include "modbus/log_limiter.hpp"

#include <gtest/gtest.h>

#include <vector>

#include "support/log_capture.hpp"

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
    Clock::duration span{};
    auto report = [&](LogCause c, std::uint64_t n, Clock::duration s) {
        seen.emplace_back(c, n);
        span = s;
    };
    l.flush(t0 + 9s, report);
    EXPECT_TRUE(seen.empty()) << "no summary before the window ends";
    // Flushed late (a UDP listener flushes at its next datagram): the span says how late.
    l.flush(t0 + 14s, report);
    ASSERT_EQ(seen.size(), 1u);
    EXPECT_EQ(seen[0].first, LogCause::RefusedFull);
    EXPECT_EQ(seen[0].second, 10u);
    EXPECT_EQ(span, 14s);
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

TEST(LogLimiter, FlushToLogWritesOneWarningPerCauseWithItsPrefixCountAndWindow) {
    testing::LogCapture log("log-limiter-test");
    LogLimiter l(1, 2s);
    const Clock::time_point t0{1h};
    for (int i = 0; i < 5; ++i) l.allow(LogCause::BadHeader, t0);
    for (int i = 0; i < 3; ++i) l.allow(LogCause::Connected, t0);
    l.flush_to_log(t0 + 1s, "mbus: 127.0.0.1:502: ");
    EXPECT_EQ(log.log(), "");
    l.flush_to_log(t0 + 2s, "mbus: 127.0.0.1:502: ");
    EXPECT_EQ(log.count("mbus: 127.0.0.1:502: 4 more bad MBAP headers in the last 2 s (not logged "
                        "one by one)"),
              1U);
    EXPECT_EQ(log.count("mbus: 127.0.0.1:502: 2 more connects in the last 2 s"), 1U);
}

}  // namespace
}  // namespace plcemu::modbus
