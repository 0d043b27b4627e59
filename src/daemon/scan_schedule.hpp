#pragma once
// The deadline arithmetic of one PLC's scan loop, a pure function of the `now` each call is
// given: which simulated time the next scan has, when in real time it is due at the time scale,
// what happens to scans that came late, freeze, and the steps queued while frozen. It reads no
// clock and knows no event loop; the ScanDriver reads the clock and runs the scans it says are
// due (docs/simulator-and-plant.md, "Simulator-control unit").

#include <chrono>
#include <cstdint>

#include "plcemu/engine/engine.hpp"

namespace plcemu::daemon {

/// When the scans of one PLC are due.
class ScanSchedule {
public:
    using Clock = std::chrono::steady_clock;
    using TimePoint = Clock::time_point;

    /// Scans that may be queued at once (46 simulated hours at 10 ms).
    static constexpr std::uint64_t kMaxPendingSteps = 16'777'215;
    /// Further behind real time than this, the schedule stops trying to catch up.
    static constexpr std::chrono::seconds kMaxBehind{1};

    /// Due scans are counted up to this many (over 100 simulated days at 10 ms).
    static constexpr std::uint64_t kMaxDue = std::uint64_t{1} << 30;

    /// What is due at a given real time.
    struct Due {
        std::uint64_t scans =
            0;  ///< scans whose deadline has come (0 while frozen; kMaxDue at most)
        TimePoint next_deadline;  ///< when the next scan is due (TimePoint::max() while frozen)
    };

    /// `period`: the engine's scan period (simulated time); `time_scale`: simulated seconds per
    /// real second.
    ScanSchedule(engine::Duration period, double time_scale) noexcept
        : period_(period),
          scale_(time_scale) {}

    /// (Re)starts the schedule: the next scan has simulated time `next_sim` and is due at
    /// `first`, then one every period divided by the time scale.
    void start(engine::Duration next_sim, TimePoint first) noexcept;
    /// What is due at `now`.
    Due due(TimePoint now) const noexcept;
    /// Simulated time of the next scan.
    engine::Duration next_sim() const noexcept { return next_sim_; }
    /// The real time the scan at simulated time `sim` is due, at the present time scale.
    TimePoint deadline(engine::Duration sim) const noexcept;
    /// The next scan ran: its successor is one period later in simulated time.
    void ran() noexcept { next_sim_ += period_; }
    /// More than kMaxBehind behind real time at `now` (a host too slow for the time scale): the
    /// scans missed are given up, and the next is due at `now`, without a jump in simulated
    /// time. Returns true when it skipped.
    bool skip_ahead(TimePoint now) noexcept;

    /// The time scale.
    double time_scale() const noexcept { return scale_; }
    /// Changes the time scale at `now` without a jump in simulated time: the next scan is due at
    /// `now`, and later ones at the new scale.
    void set_time_scale(double scale, TimePoint now) noexcept;
    /// True while frozen.
    bool frozen() const noexcept { return frozen_; }
    /// Freezes (no scan is due) or, at `now`, resumes: the next scan is due at `now`, simulated
    /// time going on from where it stopped. Returns false when nothing changed.
    bool set_frozen(bool frozen, TimePoint now) noexcept;

    /// Queues `n` scans (meant for a frozen PLC), up to kMaxPendingSteps in all.
    void queue_steps(std::uint64_t n) noexcept;
    /// Scans queued and not yet run.
    std::uint64_t pending_steps() const noexcept { return pending_steps_; }
    /// Drops the queued scans.
    void cancel_steps() noexcept { pending_steps_ = 0; }
    /// A queued scan, at next_sim(), ran and ended at `now`: a running (not frozen) PLC goes on
    /// in real time from `now`, not catching up on the scans the steps took the place of.
    void stepped(TimePoint now) noexcept;

private:
    void rebase(TimePoint now) noexcept {
        base_real_ = now;
        base_sim_ = next_sim_;
    }

    engine::Duration period_;
    double scale_;
    bool frozen_ = false;
    std::uint64_t pending_steps_ = 0;
    TimePoint base_real_{};  // the real time at which simulated time was base_sim_
    engine::Duration base_sim_{0};
    engine::Duration next_sim_{0};
};

}  // namespace plcemu::daemon
