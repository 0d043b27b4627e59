#pragma once
// The scans queued by the simulator unit's "step N scans", of every PLC of the process, run in
// rounds: each turn of the event loop runs one slice of about a millisecond, one scan per
// stepping PLC in turn, and then lets the I/O waiting on the loop in. A read of any PLC thus
// waits for one slice, however many PLCs are stepped (DESIGN principle 14, docs/performance.md).

#include <asio.hpp>
#include <chrono>
#include <deque>
#include <memory>

namespace plcemu::daemon {

/// A PLC with queued steps (a ScanDriver).
class Stepper {
public:
    /// Runs the next queued scan if one is left; false when none is left after it.
    virtual bool step_once() noexcept = 0;

protected:
    ~Stepper() = default;
};

/// The process's one queue of stepping PLCs, served round-robin a slice at a time.
class StepRounds {
public:
    using Clock = std::chrono::steady_clock;
    /// Longest stretch of stepping before the loop lets I/O in (at least one scan runs).
    static constexpr auto kSlice = std::chrono::milliseconds(1);

    explicit StepRounds(asio::io_context& io, Clock::duration slice = kSlice)
        : io_(io),
          slice_(slice) {}
    StepRounds(const StepRounds&) = delete;
    StepRounds& operator=(const StepRounds&) = delete;

    /// Takes `s` into the rounds (once: a stepper already in them keeps its place).
    void add(Stepper& s) noexcept;
    /// Takes `s` out; it may be freed afterwards.
    void remove(Stepper& s) noexcept;
    /// Steppers in the rounds.
    std::size_t size() const noexcept { return queue_.size(); }

private:
    void post();
    void round();

    asio::io_context& io_;
    Clock::duration slice_;
    std::deque<Stepper*> queue_;  // the next to scan first
    bool posted_ = false;
    // A round already posted when the rounds are destroyed finds this expired.
    std::shared_ptr<char> alive_ = std::make_shared<char>();
};

}  // namespace plcemu::daemon
