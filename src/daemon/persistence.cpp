#include "persistence.hpp"

#include <spdlog/spdlog.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cerrno>
#include <condition_variable>
#include <cstring>
#include <mutex>
#include <system_error>
#include <thread>

#include "daemon/background.hpp"
#include "plcemu/daemon/plc.hpp"

namespace plcemu::daemon {

SyncThread::~SyncThread() {
    {
        std::lock_guard lock(mutex_);
        stop_ = true;
    }
    cv_.notify_all();
    if (thread_.joinable()) thread_.join();
    limiter_.flush_to_log(Clock::now(), "persistence: ", true);
}

SyncThread::Id SyncThread::add(image::StateFile& file,
                               std::chrono::milliseconds period,
                               std::string prefix) {
    Id id = 0;
    {
        std::lock_guard lock(mutex_);
        id = next_++;
        entries_.push_back(
            {id, &file, period, Clock::now() + period, false, false, std::move(prefix)});
        changed_ = true;
    }
    cv_.notify_all();
    if (!thread_.joinable()) thread_ = std::thread([this] { run(); });
    return id;
}

void SyncThread::set_period(Id id, std::chrono::milliseconds period) {
    {
        std::lock_guard lock(mutex_);
        for (auto& e : entries_) {
            if (e.id == id && e.period != period) {
                e.period = period;
                e.due = Clock::now() + period;
            }
        }
        changed_ = true;
    }
    cv_.notify_all();
}

void SyncThread::remove(Id id) {
    {
        std::unique_lock lock(mutex_);
        cv_.wait(lock, [&] { return syncing_ != id; });
        std::erase_if(entries_, [id](const Entry& e) { return e.id == id; });
        changed_ = true;
    }
    cv_.notify_all();
}

void SyncThread::run() {
    yield_to_the_loop();
    std::unique_lock lock(mutex_);
    while (!stop_) {
        changed_ = false;
        if (entries_.empty()) {
            cv_.wait(lock, [&] { return stop_ || changed_; });
            continue;
        }
        const auto next =
            std::min_element(entries_.begin(), entries_.end(), [](const Entry& a, const Entry& b) {
                return a.due < b.due;
            })->due;
        if (cv_.wait_until(lock, next, [&] { return stop_ || changed_; })) continue;
        // Every file due now, one at a time with the lock released: a slow disk holds up only
        // this thread, and remove() waits for the one file it names.
        const auto now = Clock::now();
        std::vector<Id> due;
        for (auto& e : entries_) {
            if (e.due <= now) {
                due.push_back(e.id);
                e.due = now + e.period;
            }
        }
        // Ids grow along entries_ (add() appends, remove() erases): a file is found by a binary
        // search, not by a scan of every file for each (5,000 PLCs sync 5,000 files a second).
        const auto find = [this](Id id) {
            const auto it = std::lower_bound(entries_.begin(), entries_.end(), id,
                                             [](const Entry& e, Id v) { return e.id < v; });
            return it != entries_.end() && it->id == id ? it : entries_.end();
        };
        for (const Id id : due) {
            auto it = find(id);
            if (it == entries_.end() || stop_) continue;
            image::StateFile* file = it->file;
            const bool said_gone = it->gone;
            syncing_ = id;
            lock.unlock();
            const std::uint64_t pages = file->pages_synced();
            const int error = file->sync() ? 0 : errno;
            census_.pages_synced.fetch_add(file->pages_synced() - pages, std::memory_order_relaxed);
            // Once said gone, a file is not looked for again (two system calls a sync).
            const bool in_place = said_gone || file->in_place();
            lock.lock();
            it = find(id);
            if (it != entries_.end()) {
                synced(*it, error);
                moved(*it, in_place);
            }
            syncing_ = 0;
            cv_.notify_all();
        }
        limiter_.flush_to_log(Clock::now(), "persistence: ");
    }
}

// A state file deleted, moved away or replaced while in use is said once: its PLC runs on, but
// what it keeps from now on goes to a file no start will find.
void SyncThread::moved(Entry& e, bool in_place) {
    if (in_place || e.gone) return;
    e.gone = true;
    if (limiter_.allow(modbus::LogCause::StateFileGone, Clock::now())) {
        spdlog::warn(
            "{}persistence: {}: the state file was deleted or moved away while in use; the PLC "
            "runs on, syncing the file it holds open, which the next start will not find: put "
            "the file back at its path before the stop (a deleted one can be copied from "
            "/proc/{}/fd/) or the next start begins without its retentive values",
            e.prefix, e.file->path(), ::getpid());
    }
}

// Counts a sync (`error`: 0, or the errno it failed with); a file's failure is logged when an
// episode of them begins, and its recovery when it ends, so that a failing disk cannot fill the
// log. Each file keeps its own episode: one that fails does not make another's sync news. Many
// files beginning or ending an episode at once (one disk under all of them) are a few lines
// each way and a count.
void SyncThread::synced(Entry& e, int error) {
    const auto now = Clock::now();
    if (error == 0) {
        census_.syncs.fetch_add(1, std::memory_order_relaxed);
        if (e.failing && limiter_.allow(modbus::LogCause::SyncResumed, now))
            spdlog::info("{}persistence: {}: syncing again", e.prefix, e.file->path());
        e.failing = false;
        return;
    }
    census_.sync_failures.fetch_add(1, std::memory_order_relaxed);
    if (!e.failing && limiter_.allow(modbus::LogCause::SyncFailed, now)) {
        spdlog::error(
            "{}persistence: {}: sync failed ({}); the state stays in memory and is "
            "synced again every period",
            e.prefix, e.file->path(), std::strerror(error));
    }
    e.failing = true;
}

void open_state_files(const std::vector<const config::Config*>& configs,
                      const std::string& state_directory,
                      std::time_t now,
                      const std::function<void(std::size_t, OpenedState)>& opened) {
    const std::size_t count = configs.size();
    std::vector<OpenedState> out(count);
    std::vector<char> done(count, 0);  // out[i] is final (under `mutex`)
    std::mutex mutex;
    std::condition_variable cv;  // only the calling thread waits on it
    std::atomic<std::size_t> next{0};
    const auto make = [&](std::size_t i) {
        const config::Config& c = *configs[i];
        if (c.persistence.enabled) {
            try {
                out[i].file = std::make_unique<image::StateFile>(
                    config::state_file_path(c, state_directory), plc_layout(c), now);
            } catch (...) {
                out[i].error = std::current_exception();
            }
        }
        {
            std::lock_guard lock(mutex);
            done[i] = 1;
        }
        cv.notify_one();
    };
    const auto work = [&] {
        for (std::size_t i = next++; i < count; i = next++) make(i);
    };
    // The threads wait for the disk, not for a core: more than the cores, few enough that a
    // small config starts none.
    constexpr std::size_t kThreads = 8;
    constexpr std::size_t kPerThread = 32;
    struct Threads {
        std::atomic<std::size_t>& next;
        std::size_t count;
        std::vector<std::thread> list;
        // However the calling thread leaves: no file is begun any more, and the threads end
        // before what they write into goes.
        ~Threads() {
            next = count;
            for (auto& t : list) t.join();
        }
    } threads{next, count, {}};
    try {
        for (std::size_t t = 0; t < std::min(kThreads, count / kPerThread); ++t) {
            threads.list.emplace_back(work);
        }
    } catch (const std::system_error&) {
        // No further thread to be had (a process limit): the ones started and this one share
        // the files.
    }
    for (std::size_t i = 0; i < count; ++i) {
        for (;;) {
            {
                std::lock_guard lock(mutex);
                if (done[i] != 0) break;
            }
            // Rather than wait, the calling thread makes the first file no thread has begun
            // (the i-th itself when there are no threads).
            if (const std::size_t j = next++; j < count) {
                make(j);
                continue;
            }
            std::unique_lock lock(mutex);
            cv.wait(lock, [&] { return done[i] != 0; });
            break;
        }
        opened(i, std::move(out[i]));
    }
}

}  // namespace plcemu::daemon
