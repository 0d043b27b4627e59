#pragma once
// Where the state file lives, and the thread that writes it to disk on a timer.

#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <ctime>
#include <exception>
#include <functional>
#include <memory>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "plcemu/config/config.hpp"
#include "plcemu/config/listener_key.hpp"
#include "plcemu/image/state_file.hpp"
#include "plcemu/listener/census.hpp"
#include "modbus/log_limiter.hpp"

namespace plcemu::daemon {

/// Syncs the state files of every PLC of the process, each every period of its own, on one
/// thread: msync may wait for the disk, and the scan loop must not (and 500 PLCs need not 500
/// threads). The thread starts with the first file.
class SyncThread {
public:
    /// A file's place on the thread.
    using Id = std::uint64_t;

    /// Counts its syncs and their failures into `census`, which must outlive it.
    explicit SyncThread(listener::Census& census)
        : census_(census) {}
    /// Stops (a last sync is each owner's close()).
    ~SyncThread();
    SyncThread(const SyncThread&) = delete;
    SyncThread& operator=(const SyncThread&) = delete;

    /// Starts syncing `file` every `period`; `prefix` starts its lines ("plcs[1] (kiln): ", or
    /// empty for a config's one PLC).
    Id add(image::StateFile& file, std::chrono::milliseconds period, std::string prefix = {});
    /// Changes a file's period (reload).
    void set_period(Id id, std::chrono::milliseconds period);
    /// Stops syncing the file (waiting for a sync of it under way); it may be closed afterwards.
    void remove(Id id);

private:
    using Clock = std::chrono::steady_clock;
    struct Entry {
        Id id;
        image::StateFile* file;
        std::chrono::milliseconds period;
        Clock::time_point due;
        bool failing = false;  // its last sync failed: the next failure is not logged again
        bool gone = false;     // it was found deleted or moved away (said once)
        std::string prefix;    // its PLC's, as its other lines start
    };
    void run();
    void synced(Entry& e, int error);
    void moved(Entry& e, bool in_place);

    std::mutex mutex_;
    std::condition_variable cv_;
    std::vector<Entry> entries_;
    Id next_ = 1;
    Id syncing_ = 0;  // the file being synced now, 0 = none
    bool changed_ = false;
    bool stop_ = false;
    // The lines of failures and recoveries: a few each 2 s, the rest summed up (one disk under
    // 5,000 files would otherwise log 5,000 lines each way).
    modbus::LogLimiter limiter_{5, std::chrono::seconds(2)};
    listener::Census& census_;
    std::thread thread_;
};

/// A PLC's state file as opened before its PLC starts: the file, or why it could not be had.
struct OpenedState {
    std::unique_ptr<image::StateFile> file;  ///< null without persistence, or when it failed
    std::exception_ptr error;                ///< what opening it threw
};

/// Opens the state file of every config with persistence, a few at a time on threads of their
/// own: made anew, a file costs two fsyncs, and 5,000 of them one after another keep a start
/// waiting for the disk for seconds, where the disk's journal commits the fsyncs of files made
/// at once together. `state_directory` is $STATE_DIRECTORY (or empty). Each file is opened as
/// the PLC would have opened it itself. `opened(i, state)` is called on the calling thread for
/// every config in order, as soon as its file is had, while the threads make the next ones (a
/// start builds each PLC meanwhile); what it throws stops the making of files not yet begun and
/// comes out of open_state_files once the threads ended.
void open_state_files(const std::vector<const config::Config*>& configs,
                      const std::string& state_directory,
                      std::time_t now,
                      const std::function<void(std::size_t, OpenedState)>& opened);

}  // namespace plcemu::daemon
