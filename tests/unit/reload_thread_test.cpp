// A reload's preparing thread: its result is delivered, unless a shutdown abandoned it first
// (docs/operations.md, "Reload (SIGHUP)").

#include "daemon/reload_thread.hpp"

#include <gtest/gtest.h>
#include <sys/resource.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <memory>
#include <thread>

namespace plcemu::daemon {
namespace {

using namespace std::chrono_literals;

void wait_for(const std::atomic<bool>& flag) {
    for (int i = 0; i < 500 && !flag; ++i) std::this_thread::sleep_for(10ms);
}

// Preparing a big config takes seconds of a core: the thread yields to the event loop (its
// nice value 10 above the process's; docs/architecture.md, "Threads").
TEST(ReloadThread, PreparesBelowTheCallersPriority) {
    ReloadThread t;
    auto seen = std::make_shared<std::atomic<int>>(-100);
    auto delivered = std::make_shared<std::atomic<bool>>(false);
    const int process = ::getpriority(PRIO_PROCESS, static_cast<id_t>(::getpid()));
    const int mine = ::getpriority(PRIO_PROCESS, static_cast<id_t>(::gettid()));
    t.start([seen] { *seen = ::getpriority(PRIO_PROCESS, static_cast<id_t>(::gettid())); },
            [delivered] { *delivered = true; });
    wait_for(*delivered);
    ASSERT_TRUE(*delivered);
    EXPECT_EQ(*seen, std::min(process + 10, 19));
    EXPECT_EQ(::getpriority(PRIO_PROCESS, static_cast<id_t>(::gettid())), mine);
    t.join();
}

TEST(ReloadThread, DeliversWhatItPreparedOnItsThread) {
    ReloadThread t;
    auto delivered = std::make_shared<std::atomic<bool>>(false);
    auto prepared = std::make_shared<std::atomic<int>>(0);
    t.start([prepared] { *prepared = 42; },
            [prepared, delivered] { *delivered = *prepared == 42; });
    wait_for(*delivered);
    EXPECT_TRUE(*delivered);
    // A thread that delivered is no longer working: nothing is left behind.
    EXPECT_FALSE(t.abandon());
    // The next reload's thread starts after the previous one.
    auto again = std::make_shared<std::atomic<bool>>(false);
    t.start([] {}, [again] { *again = true; });
    t.join();
    EXPECT_TRUE(*again);
}

TEST(ReloadThread, AnAbandonedThreadNeverDeliversAndIsNotWaitedFor) {
    auto release = std::make_shared<std::atomic<bool>>(false);
    auto finished = std::make_shared<std::atomic<bool>>(false);
    auto delivered = std::make_shared<std::atomic<bool>>(false);
    {
        ReloadThread t;
        t.start(
            [release, finished] {
                wait_for(*release);  // a config that takes long to build
                *finished = true;
            },
            [delivered] { *delivered = true; });
        const auto t0 = std::chrono::steady_clock::now();
        EXPECT_TRUE(t.abandon());
        EXPECT_LT(std::chrono::steady_clock::now() - t0, 1s);
    }  // destroyed at once: the thread was detached
    *release = true;
    wait_for(*finished);
    std::this_thread::sleep_for(50ms);
    EXPECT_TRUE(*finished);
    EXPECT_FALSE(*delivered);
}

}  // namespace
}  // namespace plcemu::daemon
