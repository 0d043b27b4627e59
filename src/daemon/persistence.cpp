#include "persistence.hpp"

namespace plcemu::daemon {

std::string state_file_path(const config::Config& config, const std::string& state_directory) {
    std::string name = config::default_state_file(config);
    if (name.front() == '/') return name;
    std::string dir = state_directory.substr(0, state_directory.find(':'));
    if (dir.empty()) {
        const auto slash = config.path.rfind('/');
        if (slash == std::string::npos) {
            dir.assign(1, '.');
        } else if (slash == 0) {
            dir.assign(1, '/');
        } else {
            dir.assign(config.path, 0, slash);
        }
    }
    if (dir.back() != '/') dir += '/';
    dir += name;
    return dir;
}

SyncThread::SyncThread(image::StateFile& file, std::chrono::milliseconds period)
    : file_(file),
      period_(period),
      thread_([this] { run(); }) {}

SyncThread::~SyncThread() {
    {
        std::lock_guard lock(mutex_);
        stop_ = true;
    }
    cv_.notify_all();
    thread_.join();
}

void SyncThread::set_period(std::chrono::milliseconds period) {
    {
        std::lock_guard lock(mutex_);
        period_ = period;
    }
    cv_.notify_all();
}

void SyncThread::run() {
    std::unique_lock lock(mutex_);
    while (!stop_) {
        const auto period = period_;
        if (cv_.wait_for(lock, period, [&] { return stop_ || period_ != period; })) continue;
        lock.unlock();
        file_.sync();
        lock.lock();
    }
}

}  // namespace plcemu::daemon
