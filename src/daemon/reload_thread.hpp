#pragma once
// The thread a reload prepares on (reading, validating and building the new config), which a
// shutdown does not wait for: a config that takes seconds to build must not hold up SIGTERM.

#include <functional>
#include <memory>
#include <mutex>
#include <thread>

namespace plcemu::daemon {

/// One reload's preparing thread at a time.
class ReloadThread {
public:
    ReloadThread() = default;
    /// Waits for a thread still preparing (only an exception leaves the loop without abandon()).
    ~ReloadThread() { join(); }
    ReloadThread(const ReloadThread&) = delete;
    ReloadThread& operator=(const ReloadThread&) = delete;

    /// Runs `work` on a thread of its own and then `deliver` on that thread, unless abandon()
    /// came first. `work` must use nothing the caller owns: after abandon() it runs on alone.
    /// The previous thread must have delivered (it is joined here). Without a thread to be had,
    /// runs both here.
    void start(const std::function<void()>& work, const std::function<void()>& deliver);

    /// Gives up a thread still working: it never calls `deliver` after this returns, and is left
    /// to run on, detached, while the process exits. Returns true when one was left working.
    bool abandon();

    /// Waits for the thread, if any.
    void join() noexcept;

private:
    struct Shared {
        std::mutex mutex;
        bool abandoned = false;
        bool delivered = false;
    };
    std::shared_ptr<Shared> shared_;
    std::thread thread_;
};

}  // namespace plcemu::daemon
