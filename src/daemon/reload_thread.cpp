#include "daemon/reload_thread.hpp"

#include <spdlog/spdlog.h>

#include <system_error>

#include "daemon/background.hpp"

namespace plcemu::daemon {

void ReloadThread::start(const std::function<void()>& work, const std::function<void()>& deliver) {
    join();
    auto shared = std::make_shared<Shared>();
    try {
        // The lambda holds copies: a thread that cannot be had leaves `work` and `deliver` here.
        thread_ = std::thread([shared, work, deliver] {
            yield_to_the_loop();
            work();
            std::lock_guard lock(shared->mutex);
            if (!shared->abandoned) deliver();
            shared->delivered = true;
        });
        shared_ = std::move(shared);
    } catch (const std::system_error& e) {
        spdlog::warn("reload: no thread ({}); preparing on the event loop", e.what());
        work();
        deliver();
    }
}

bool ReloadThread::abandon() {
    if (!thread_.joinable()) return false;
    {
        std::lock_guard lock(shared_->mutex);
        if (!shared_->delivered) {
            shared_->abandoned = true;
            thread_.detach();
            return true;
        }
    }
    thread_.join();  // it has delivered and is ending
    return false;
}

void ReloadThread::join() noexcept {
    if (thread_.joinable()) thread_.join();
}

}  // namespace plcemu::daemon
