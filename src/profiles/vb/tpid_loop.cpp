#include "profiles/vb/tpid_loop.hpp"

#include <algorithm>
#include <cmath>

namespace plcemu::profiles::vb::tpid {

namespace {

double held(double v) noexcept { return std::clamp(v, 0.0, static_cast<double>(kFullScale)); }

// Kp' in output units (0.1 %) per PV unit, with the sensitivity's gain factor.
double gain(const Settings& s) noexcept { return 0.01 * s.kp * s.gain_factor; }

// E > 0 when the channel needs output: PV below SV when heating, above it when cooling.
double error(const Settings& s, int sv, int pv) noexcept {
    return s.forward ? static_cast<double>(pv) - sv : static_cast<double>(sv) - pv;
}

}  // namespace

void Loop::start(const Settings& s) noexcept {
    *this = Loop{};
    manual_ = s.manual;
    // The start-up phase belongs to a channel that starts in auto; scan() ends it at once when
    // R = 0.
    armed_ = !s.manual;
}

void Loop::resume(const Settings& s, double e, double value) noexcept {
    integral_ = held(value - gain(s) * e);
    armed_ = false;
}

void Loop::scan(const Settings& s, int sv, int pv, double dt_s) noexcept {
    const double e = error(s, sv, pv);
    if (s.manual) {
        // A manual channel runs no experiment (its AT bit waits) and has no start-up phase.
        tuning_ = false;
        armed_ = false;
        manual_ = true;
        return;
    }
    if (manual_) {
        // Manual → auto: the output continues from the user's value.
        manual_ = false;
        resume(s, e, s.manual_value);
    }
    if (tuning_ && !s.tune) {
        // The AT bit cleared by a master or the program: the experiment is abandoned and the
        // PID takes over from the relay's output.
        tuning_ = false;
        resume(s, e, output_);
    }
    if (tuning_) {
        relay_.observe(pv);
        return;
    }
    if (armed_ && (s.r <= 0 || std::abs(e) <= s.r)) armed_ = false;
    const double ti = 0.1 * s.ti * s.time_factor;
    if (!armed_ && ti > 0) integral_ = held(integral_ + gain(s) * e * dt_s / ti);
}

Cycle Loop::boundary(
    const Settings& s, int sv, int pv, engine::Duration now, double cycle_s) noexcept {
    const double e = error(s, sv, pv);
    Cycle out;
    if (manual_) {
        output_ = s.manual_value;
    } else {
        if (!tuning_ && s.tune) {
            tuning_ = true;
            armed_ = false;
            relay_.start(now);
            relay_.observe(pv);
        }
        if (tuning_) {
            const bool measured = relay_.decide(now, e > 0) == RelayExperiment::State::Measured;
            output_ = relay_.high() ? kFullScale : 0;
            if (measured) {
                tuning_ = false;
                const RelayCycle& c = relay_.cycle();
                Settings tuned = s;
                if (c.a > 0) {
                    out.tuning = Tuning::Done;
                    out.gains = ziegler_nichols(kFullScale, c);
                    tuned.kp = out.gains.kp;
                    tuned.ti = out.gains.ti;
                    tuned.td = out.gains.td;
                } else {
                    out.tuning = Tuning::Failed;
                }
                // Normal control starts from the relay's mean output, and its first cycle has
                // no derivative kick from the oscillation.
                integral_ = held(kFullScale * c.duty());
                have_pv_ = false;
                output_ = solve(tuned, e, pv, cycle_s);
            }
        } else {
            output_ = solve(s, e, pv, cycle_s);
        }
        out.write_output = true;
    }
    pv_prev_ = pv;
    e_prev_ = std::abs(e);
    have_pv_ = true;
    out.output = output_;
    return out;
}

int Loop::solve(const Settings& s, double e, int pv, double cycle_s) noexcept {
    double dpv = 0;
    if (have_pv_) {
        dpv = s.forward ? static_cast<double>(pv_prev_) - pv : static_cast<double>(pv) - pv_prev_;
        // The start-up phase also ends when PV stops approaching SV after it had started to:
        // a loop whose P-only offset is larger than R would otherwise stay below SV for good.
        if (armed_) {
            if (std::abs(e) < e_prev_) {
                moved_ = true;
            } else if (moved_) {
                armed_ = false;
            }
        }
    }
    const double kp = gain(s);
    const double td = 0.01 * s.td;
    const double d = cycle_s > 0 ? kp * td * dpv / cycle_s : 0.0;
    const double mv = kp * e + integral_ - d;
    return static_cast<int>(std::lround(held(mv)));
}

}  // namespace plcemu::profiles::vb::tpid
