// The reload's retired PLCs are destroyed off the event loop, in order, and none is lost.

#include "daemon/retirer.hpp"

#include <gtest/gtest.h>
#include <sys/resource.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <thread>
#include <vector>

namespace plcemu::daemon {
namespace {

struct Tracked {
    Tracked(std::vector<int>& log, std::mutex& m, int id, std::thread::id* where)
        : log_(log),
          m_(m),
          id_(id),
          where_(where) {}
    ~Tracked() {
        std::this_thread::sleep_for(std::chrono::milliseconds(20));  // a big program
        std::lock_guard lock(m_);
        log_.push_back(id_);
        if (where_) *where_ = std::this_thread::get_id();
    }
    std::vector<int>& log_;
    std::mutex& m_;
    int id_;
    std::thread::id* where_;
};

TEST(Retirer, DestroysOffTheCallersThreadInOrderWithoutBlockingIt) {
    std::vector<int> log;
    std::mutex m;
    std::thread::id where;
    Retirer<Tracked> r;
    const auto t0 = std::chrono::steady_clock::now();
    for (int i = 0; i < 5; ++i) r.retire(std::make_unique<Tracked>(log, m, i, &where));
    // Five 20 ms destructions queued without waiting for any of them.
    EXPECT_LT(std::chrono::steady_clock::now() - t0, std::chrono::milliseconds(50));
    r.stop();
    EXPECT_EQ(log, (std::vector<int>{0, 1, 2, 3, 4}));
    EXPECT_NE(where, std::this_thread::get_id());
}

// Destroying a big program takes a while: the destroying thread yields to the event loop (its
// nice value 10 above the process's; docs/architecture.md, "Threads").
TEST(Retirer, DestroysBelowTheCallersPriority) {
    struct Niceness {
        int* seen;
        ~Niceness() { *seen = ::getpriority(PRIO_PROCESS, static_cast<id_t>(::gettid())); }
    };
    const int process = ::getpriority(PRIO_PROCESS, static_cast<id_t>(::getpid()));
    const int mine = ::getpriority(PRIO_PROCESS, static_cast<id_t>(::gettid()));
    int seen = -100;
    Retirer<Niceness> r;
    r.retire(std::unique_ptr<Niceness>(new Niceness{&seen}));
    r.stop();
    EXPECT_EQ(seen, std::min(process + 10, 19));
    EXPECT_EQ(::getpriority(PRIO_PROCESS, static_cast<id_t>(::gettid())), mine);
}

// Stopping twice is harmless, and an object retired after the stop is not lost: the next stop
// (or the destructor) frees it, on the caller's thread since no thread runs any more.
TEST(Retirer, StopWithNothingQueuedAndTwiceIsFineAndALaterRetireIsStillDestroyed) {
    std::vector<int> log;
    std::mutex m;
    std::thread::id where;
    Retirer<Tracked> r;
    r.stop();
    r.stop();
    r.retire(std::make_unique<Tracked>(log, m, 7, &where));
    EXPECT_TRUE(log.empty());
    r.stop();
    EXPECT_EQ(log, (std::vector<int>{7}));
    EXPECT_EQ(where, std::this_thread::get_id());
}

}  // namespace
}  // namespace plcemu::daemon
