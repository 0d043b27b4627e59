#include "scan_schedule.hpp"

#include <algorithm>
#include <cmath>

namespace plcemu::daemon {

void ScanSchedule::start(engine::Duration next_sim, TimePoint first) noexcept {
    next_sim_ = next_sim;
    rebase(first);
}

ScanSchedule::TimePoint ScanSchedule::deadline(engine::Duration sim) const noexcept {
    const auto real = std::chrono::duration<double, std::nano>(
        static_cast<double>((sim - base_sim_).count()) / scale_);
    return base_real_ + std::chrono::duration_cast<Clock::duration>(real);
}

ScanSchedule::Due ScanSchedule::due(TimePoint now) const noexcept {
    if (frozen_) return {0, TimePoint::max()};
    const TimePoint next = deadline(next_sim_);
    if (next > now) return {0, next};
    // The periods that fit between the deadline and `now`, estimated in floating point and then
    // made exact against deadline(): a scan is due when its own deadline has come. Counted up
    // to kMaxDue, which keeps the simulated times summed below far from overflowing.
    const double periods = std::floor(static_cast<double>((now - next).count()) * scale_ /
                                      static_cast<double>(period_.count()));
    auto n = static_cast<std::uint64_t>(std::clamp(periods, 0.0, double(kMaxDue - 1))) + 1;
    const auto at = [&](std::uint64_t k) {
        return deadline(next_sim_ + period_ * static_cast<engine::Duration::rep>(k));
    };
    while (n < kMaxDue && at(n) <= now) ++n;
    while (n > 1 && at(n - 1) > now) --n;
    return {n, next};
}

bool ScanSchedule::skip_ahead(TimePoint now) noexcept {
    if (now - deadline(next_sim_) <= kMaxBehind) return false;
    rebase(now);
    return true;
}

void ScanSchedule::set_time_scale(double scale, TimePoint now) noexcept {
    rebase(now);
    scale_ = scale;
}

bool ScanSchedule::set_frozen(bool frozen, TimePoint now) noexcept {
    if (frozen == frozen_) return false;
    frozen_ = frozen;
    if (!frozen_) rebase(now);
    return true;
}

void ScanSchedule::queue_steps(std::uint64_t n) noexcept {
    // A bound on what clients can queue: hours of simulated time, never an endless busy loop.
    pending_steps_ = std::min(pending_steps_ + std::min(n, kMaxPendingSteps), kMaxPendingSteps);
}

void ScanSchedule::stepped(TimePoint now) noexcept {
    ran();
    if (pending_steps_ > 0) --pending_steps_;
    if (!frozen_) rebase(now);
}

}  // namespace plcemu::daemon
