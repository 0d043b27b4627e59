#include "persistence.hpp"

#include <spdlog/spdlog.h>

#include <algorithm>
#include <cerrno>
#include <cstring>

namespace plcemu::daemon {

SyncThread::~SyncThread() {
    {
        std::lock_guard lock(mutex_);
        stop_ = true;
    }
    cv_.notify_all();
    if (thread_.joinable()) thread_.join();
}

SyncThread::Id SyncThread::add(image::StateFile& file, std::chrono::milliseconds period) {
    Id id = 0;
    {
        std::lock_guard lock(mutex_);
        id = next_++;
        entries_.push_back({id, &file, period, Clock::now() + period});
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
        for (const Id id : due) {
            auto it = std::find_if(entries_.begin(), entries_.end(),
                                   [id](const Entry& e) { return e.id == id; });
            if (it == entries_.end() || stop_) continue;
            image::StateFile* file = it->file;
            syncing_ = id;
            lock.unlock();
            const int error = file->sync() ? 0 : errno;
            lock.lock();
            // Found again: remove() of another file may have moved it meanwhile.
            it = std::find_if(entries_.begin(), entries_.end(),
                              [id](const Entry& e) { return e.id == id; });
            if (it != entries_.end()) synced(*it, error);
            syncing_ = 0;
            cv_.notify_all();
        }
    }
}

// Counts a sync (`error`: 0, or the errno it failed with); a file's failure is logged when an
// episode of them begins, and its recovery when it ends, so that a failing disk cannot fill the
// log. Each file keeps its own episode: one that fails does not make another's sync news.
void SyncThread::synced(Entry& e, int error) {
    if (error == 0) {
        census_.syncs.fetch_add(1, std::memory_order_relaxed);
        if (e.failing) spdlog::info("persistence: {}: syncing again", e.file->path());
        e.failing = false;
        return;
    }
    census_.sync_failures.fetch_add(1, std::memory_order_relaxed);
    if (!e.failing) {
        spdlog::error(
            "persistence: {}: sync failed ({}); the state stays in memory and is "
            "synced again every period",
            e.file->path(), std::strerror(error));
    }
    e.failing = true;
}

}  // namespace plcemu::daemon
