#pragma once
// One timer on the event loop for the scans of every PLC in the process: each scan driver says
// when its next scan is due, and the timer wakes for the earliest and runs every driver whose
// deadline has come. 500 PLCs scanning every 10 ms cost one timer, not 500.

#include <asio.hpp>
#include <chrono>
#include <cstdint>
#include <vector>

namespace plcemu::daemon {

/// What the scan timer runs when a deadline has come (a ScanDriver).
class Scheduled {
public:
    using Clock = std::chrono::steady_clock;
    /// Runs what is due; the driver schedules its next deadline itself. `now` is a clock read
    /// taken just before; it returns the last clock read it took (or `now`), which the next
    /// driver starts from: one read per scan, however many PLCs a wake-up runs.
    virtual Clock::time_point due(Clock::time_point now) = 0;
    /// Stages of prefetch().
    static constexpr int kPrefetchStages = 3;
    /// Warms, without waiting for memory, what due() will read: the timer calls stage 0, 1, …
    /// on the drivers due after the one running, each stage one driver nearer its turn, so
    /// each stage may read what the stage before it asked for.
    virtual void prefetch(int stage) const noexcept { (void)stage; }

protected:
    ~Scheduled() = default;
};

/// The shared scan timer.
class ScanTimer {
public:
    using Clock = std::chrono::steady_clock;
    /// A driver's place in the timer.
    using Slot = std::uint32_t;

    explicit ScanTimer(asio::io_context& io);
    ScanTimer(const ScanTimer&) = delete;
    ScanTimer& operator=(const ScanTimer&) = delete;

    /// Takes `s` on; it stays unscheduled until schedule().
    Slot add(Scheduled& s);
    /// Forgets the slot (and any deadline it had); `s` may be freed afterwards.
    void remove(Slot slot) noexcept;
    /// Calls the slot's due() at `deadline` (at once if it has passed), replacing the deadline
    /// it had.
    void schedule(Slot slot, Clock::time_point deadline);
    /// Drops the slot's deadline.
    void cancel(Slot slot) noexcept;
    /// Stops the timer for good (the loop is ending).
    void stop() noexcept;

private:
    struct Entry {
        Clock::time_point deadline;
        Slot slot;
        std::uint64_t generation;  // the slot's at schedule(); a later one makes the entry stale
        bool operator>(const Entry& o) const { return deadline > o.deadline; }
    };
    struct Member {
        Scheduled* scheduled = nullptr;
        std::uint64_t generation = 0;
        bool pending = false;
    };

    bool live(const Entry& e) const {
        const Member& m = members_[e.slot];
        return m.scheduled != nullptr && m.pending && m.generation == e.generation;
    }
    void push(Entry e);
    Scheduled* firing_member(std::size_t k) const noexcept;
    void arm();
    void fire();
    void compact();

    asio::steady_timer timer_;
    std::vector<Member> members_;
    std::vector<Slot> free_;
    std::vector<Entry> heap_;    // a min-heap on deadline; stale entries are dropped lazily
    std::vector<Entry> firing_;  // the entries due at this wake-up
    bool firing_now_ = false;
    Clock::time_point armed_ = Clock::time_point::max();
    std::size_t pending_ = 0;
    bool stopped_ = false;
};

}  // namespace plcemu::daemon
