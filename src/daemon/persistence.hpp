#pragma once
// Where the state file lives, and the thread that writes it to disk on a timer.

#include <chrono>
#include <condition_variable>
#include <mutex>
#include <string>
#include <thread>

#include "plcemu/config/config.hpp"
#include "plcemu/image/state_file.hpp"

namespace plcemu::daemon {

/// The state file of a config: persistence.file, or `<config-stem>.state`; a relative name lies
/// in $STATE_DIRECTORY (set by systemd's StateDirectory=) when set, else beside the config.
/// `state_directory` is the value of STATE_DIRECTORY ("" = unset; the first of a list counts).
std::string state_file_path(const config::Config& config, const std::string& state_directory);

/// Syncs a state file every period on its own thread: msync may wait for the disk, and the scan
/// loop must not.
class SyncThread {
public:
    /// Starts syncing `file` every `period`.
    SyncThread(image::StateFile& file, std::chrono::milliseconds period);
    /// Stops (a last sync is the owner's close()).
    ~SyncThread();
    SyncThread(const SyncThread&) = delete;
    SyncThread& operator=(const SyncThread&) = delete;

    /// Changes the period (reload).
    void set_period(std::chrono::milliseconds period);

private:
    void run();

    image::StateFile& file_;
    std::mutex mutex_;
    std::condition_variable cv_;
    std::chrono::milliseconds period_;
    bool stop_ = false;
    std::thread thread_;
};

}  // namespace plcemu::daemon
