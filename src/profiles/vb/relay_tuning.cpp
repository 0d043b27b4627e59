#include "profiles/vb/relay_tuning.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <numbers>

namespace plcemu::profiles::vb {

namespace {

std::int16_t held(double v, double lo, double hi) noexcept {
    return static_cast<std::int16_t>(std::clamp(std::round(v), lo, hi));
}

double seconds(engine::Duration d) noexcept { return std::chrono::duration<double>(d).count(); }

}  // namespace

TunedGains ziegler_nichols(double relay_span, const RelayCycle& cycle) noexcept {
    // Ku in output counts per PV count; Kp in % of that, TI in 100 ms, TD in 10 ms.
    const double ku = 4.0 * relay_span / (std::numbers::pi * cycle.a);
    return TunedGains{held(60.0 * ku, 1, 32767), held(5.0 * cycle.tau, 1, 32767),
                      held(12.5 * cycle.tau, 0, 32767)};
}

void RelayExperiment::start(engine::Duration now) noexcept {
    *this = RelayExperiment{};
    cycle_start_ = now;
    rise_ = now;
}

void RelayExperiment::observe(double pv) noexcept {
    last_pv_ = pv;
    pv_min_ = std::min(pv_min_, pv);
    pv_max_ = std::max(pv_max_, pv);
}

RelayExperiment::State RelayExperiment::decide(engine::Duration now, bool demand) noexcept {
    const bool was_high = high_;
    const bool first = !decided_;
    decided_ = true;
    high_ = demand;
    if (first) return State::Running;
    if (!was_high && high_) {
        rise_ = now;
        return State::Running;
    }
    if (!(was_high && !high_)) return State::Running;

    // A hi→lo change: the first opens the cycle that is thrown away, the second opens the
    // measured one, the third closes it.
    ++falls_;
    if (falls_ == 2) {
        cycle_start_ = now;
        pv_min_ = pv_max_ = last_pv_;
        return State::Running;
    }
    if (falls_ < 3) return State::Running;
    cycle_.tau = seconds(now - cycle_start_);
    cycle_.tau_on = seconds(now - rise_);
    cycle_.a = pv_max_ - pv_min_;
    return State::Measured;
}

}  // namespace plcemu::profiles::vb
