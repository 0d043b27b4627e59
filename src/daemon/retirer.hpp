#pragma once
// Frees objects off the event loop, one after another on a thread of its own: the PLC a reload
// replaced may hold a program of 100,000 instructions, which takes a while to destroy.

#include <condition_variable>
#include <deque>
#include <memory>
#include <mutex>
#include <system_error>
#include <thread>

#include "daemon/background.hpp"
#include "daemon/release_memory.hpp"

namespace plcemu::daemon {

/// A queue of objects to destroy and the thread that destroys them.
template <typename T>
class Retirer {
public:
    Retirer() = default;
    ~Retirer() { stop(); }
    Retirer(const Retirer&) = delete;
    Retirer& operator=(const Retirer&) = delete;

    /// Queues `p` for destruction; never blocks on an earlier one. Without a thread to be had,
    /// destroys it here.
    void retire(std::unique_ptr<T> p) noexcept {
        {
            std::lock_guard lock(mutex_);
            if (!thread_.joinable() && !stopped_) {
                try {
                    thread_ = std::thread([this] { run(); });
                } catch (const std::system_error&) {
                    return;  // `p` goes out of scope here
                }
            }
            queue_.push_back(std::move(p));
        }
        wake_.notify_one();
    }

    /// Destroys what is queued and ends the thread.
    void stop() noexcept {
        {
            std::lock_guard lock(mutex_);
            stopped_ = true;
        }
        wake_.notify_one();
        if (thread_.joinable()) thread_.join();
        queue_.clear();
    }

private:
    void run() {
        yield_to_the_loop();
        std::unique_lock lock(mutex_);
        for (;;) {
            wake_.wait(lock, [this] { return stopped_ || !queue_.empty(); });
            if (queue_.empty()) return;
            std::unique_ptr<T> p = std::move(queue_.front());
            queue_.pop_front();
            lock.unlock();
            p.reset();
            release_freed_memory();
            lock.lock();
        }
    }

    std::mutex mutex_;
    std::condition_variable wake_;
    std::deque<std::unique_ptr<T>> queue_;
    std::thread thread_;
    bool stopped_ = false;
};

}  // namespace plcemu::daemon
