#include "scan_timer.hpp"

#include <algorithm>
#include <functional>

namespace plcemu::daemon {

ScanTimer::ScanTimer(asio::io_context& io)
    : timer_(io) {}

ScanTimer::Slot ScanTimer::add(Scheduled& s) {
    Slot slot = 0;
    if (free_.empty()) {
        slot = static_cast<Slot>(members_.size());
        members_.emplace_back();
    } else {
        slot = free_.back();
        free_.pop_back();
    }
    members_[slot].scheduled = &s;
    return slot;
}

void ScanTimer::remove(Slot slot) noexcept {
    cancel(slot);
    members_[slot].scheduled = nullptr;
    ++members_[slot].generation;
    free_.push_back(slot);
}

void ScanTimer::cancel(Slot slot) noexcept {
    Member& m = members_[slot];
    if (m.pending) --pending_;
    m.pending = false;
    ++m.generation;
}

void ScanTimer::schedule(Slot slot, Clock::time_point deadline) {
    Member& m = members_[slot];
    if (!m.pending) ++pending_;
    m.pending = true;
    push({deadline, slot, ++m.generation});
    // While firing, the timer is armed once at the end, not once per driver.
    if (!firing_now_ && deadline < armed_) arm();
}

void ScanTimer::push(Entry e) {
    // Drivers that re-arm without firing (freeze, a new time scale) leave stale entries behind:
    // once they outnumber the live ones, they go.
    if (heap_.size() > 2 * pending_ + 64) compact();
    heap_.push_back(e);
    std::push_heap(heap_.begin(), heap_.end(), std::greater<>{});
}

void ScanTimer::compact() {
    std::erase_if(heap_, [this](const Entry& e) { return !live(e); });
    std::make_heap(heap_.begin(), heap_.end(), std::greater<>{});
}

void ScanTimer::arm() {
    while (!heap_.empty() && !live(heap_.front())) {
        std::pop_heap(heap_.begin(), heap_.end(), std::greater<>{});
        heap_.pop_back();
    }
    if (stopped_ || heap_.empty()) {
        armed_ = Clock::time_point::max();
        return;
    }
    armed_ = heap_.front().deadline;
    // A new expiry aborts the wait before it (its handler sees operation_aborted).
    timer_.expires_at(armed_);
    timer_.async_wait([this](const asio::error_code& ec) {
        if (ec || stopped_) return;
        fire();
    });
}

void ScanTimer::fire() {
    armed_ = Clock::time_point::max();
    auto now = Clock::now();
    // Every driver due now runs once, in deadline order; one that is still behind afterwards
    // scheduled a past deadline and runs again after the I/O waiting on the loop.
    firing_.clear();
    while (!heap_.empty() && heap_.front().deadline <= now) {
        const Entry e = heap_.front();
        std::pop_heap(heap_.begin(), heap_.end(), std::greater<>{});
        heap_.pop_back();
        if (!live(e)) continue;
        members_[e.slot].pending = false;
        --pending_;
        firing_.push_back(e);
    }
    firing_now_ = true;
    constexpr auto kStages = static_cast<std::size_t>(Scheduled::kPrefetchStages);
    for (std::size_t i = 0; i < firing_.size(); ++i) {
        // The drivers next in line are warmed while this one runs: one memory latency per
        // stage, hidden behind a scan (docs/performance.md, "Many PLCs").
        if (const Scheduled* p = firing_member(i + kStages + 1)) __builtin_prefetch(p);
        for (std::size_t s = 0; s < kStages; ++s) {
            if (const Scheduled* p = firing_member(i + kStages - s))
                p->prefetch(static_cast<int>(s));
        }
        if (Scheduled* d = firing_member(i)) now = d->due(now);
    }
    firing_now_ = false;
    arm();
}

// An earlier driver's scan may have cancelled or removed this one: only one whose deadline still
// stands runs. Null past the end.
Scheduled* ScanTimer::firing_member(std::size_t k) const noexcept {
    if (k >= firing_.size()) return nullptr;
    const Entry& e = firing_[k];
    const Member& m = members_[e.slot];
    return m.scheduled != nullptr && m.generation == e.generation ? m.scheduled : nullptr;
}

void ScanTimer::stop() noexcept {
    stopped_ = true;
    timer_.cancel();
}

}  // namespace plcemu::daemon
