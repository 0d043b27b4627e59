#include "profiles/fatek/temperature_loop.hpp"

#include <algorithm>
#include <cmath>
#include <cstdlib>

#include "profiles/fatek/special_registers.hpp"

namespace plcemu::profiles::fatek {

namespace {
using image::Area;
using image::Device;
}  // namespace

void TemperatureLoop::Point::reset_control() {
    // Everything but the over-temperature count, which watches points without PID too.
    const int n = over_scans;
    const bool o = over;
    reset();
    over_scans = n;
    over = o;
}

TemperatureLoop::TemperatureLoop(const LoopRules* rules,
                                 const LoopBlocks& blocks,
                                 double gain,
                                 bool integrate_in_band_only,
                                 int over_scale)
    : rules_(rules),
      b_(blocks),
      gain_(gain),
      band_only_(integrate_in_band_only),
      over_scale_(over_scale),
      ts_(timing(0)),
      pwm_(timing(0)) {}

std::chrono::seconds TemperatureLoop::timing(unsigned code) const {
    const auto& t = rules_->timing_seconds;
    return std::chrono::seconds(t[std::min<std::size_t>(code, t.size() - 1)]);
}

void TemperatureLoop::latch_timing(const image::Image& img) {
    const std::uint16_t t = img.word(Area::R, special::kPidTiming);
    ts_ = timing(t & 0xFFu);
    pwm_ = timing(static_cast<unsigned>(t >> 8));
}

std::uint16_t TemperatureLoop::timing_word() const {
    return static_cast<std::uint16_t>((pwm_.count() << 8) | ts_.count());
}

std::uint16_t TemperatureLoop::word(const image::Image& img, const Device& base, int i) const {
    return img.word(base.area, base.index + static_cast<std::uint32_t>(i));
}

void TemperatureLoop::set_word(image::Image& img,
                               const Device& base,
                               int i,
                               std::uint16_t v) const {
    img.set_word(base.area, base.index + static_cast<std::uint32_t>(i), v);
}

void TemperatureLoop::set_y(image::Image& img, int i, bool v) const {
    img.set_bit(b_.y.area, b_.y.index + static_cast<std::uint32_t>(i), v);
}

bool TemperatureLoop::pid_enabled(const image::Image& img, int point) const {
    const std::uint16_t w =
        img.word(Area::R, special::kPidEnable + static_cast<std::uint32_t>(point / 16));
    return ((w >> (point % 16)) & 1u) != 0;
}

void TemperatureLoop::first_execution(image::Image& img, const LoopGains& defaults) {
    if (defaults_given_) return;
    defaults_given_ = true;
    for (int i = 0; i < b_.points; ++i) {
        if (word(img, b_.pr, i) != 0) continue;
        set_word(img, b_.pr, i, defaults.kc);
        set_word(img, b_.ir, i, defaults.ki);
        set_word(img, b_.dr, i, defaults.td);
    }
}

void TemperatureLoop::stop(image::Image& img) {
    for (int i = 0; i < b_.points; ++i) {
        set_y(img, i, false);
        set_word(img, b_.out, i, 0);
    }
    // Only run() changes the points: stopped, they are still as the last stop left them.
    if (running_) {
        for (auto& p : points_) p.reset();
    }
    for (std::uint32_t w = 0; w < kLoopStatusWords; ++w)
        img.set_word(b_.status.area, b_.status.index + w, 0);
    running_ = false;
}

bool TemperatureLoop::run(engine::ScanContext& ctx,
                          bool heating,
                          const std::array<LoopInput, kLoopMaxPoints>& inputs) {
    image::Image& img = ctx.image;
    if (!running_ || heating != heating_) {
        // Start (or a change of action): solve now, start a PWM cycle now, from fresh state.
        for (auto& p : points_) p.reset();
        running_ = true;
        heating_ = heating;
        next_solve_ = ctx.now;
        cycle_start_ = ctx.now;
        cycle_due_ = true;
    }
    bool solve = false;
    if (ctx.now >= next_solve_) {
        solve = true;
        next_solve_ += ts_;
        if (next_solve_ <= ctx.now) next_solve_ = ctx.now + ts_;  // after a jump in time
    }
    if (ctx.now >= cycle_start_ + pwm_) {
        cycle_start_ += pwm_;
        if (cycle_start_ + pwm_ <= ctx.now) cycle_start_ = ctx.now;
        cycle_due_ = true;
    }
    const bool new_cycle = cycle_due_;
    cycle_due_ = false;

    const int full = rules_->full_scale;
    const int over_limit =
        std::max<int>(img.word(Area::R, special::kOverTemperature), rules_->min_over_temperature) *
        over_scale_;
    const int open_percent =
        std::clamp<int>(img.word(Area::R, special::kHeaterOpenPercent), 80, 100);
    const auto open_time = std::chrono::seconds(std::max<int>(
        img.word(Area::R, special::kHeaterOpenSeconds), rules_->min_heater_open_seconds));

    std::uint32_t in_zone = 0, warn = 0, over_bits = 0, open_bits = 0;
    bool alarm = false;
    for (int i = 0; i < b_.points; ++i) {
        Point& p = points_[static_cast<std::size_t>(i)];
        const LoopInput& in = inputs[static_cast<std::size_t>(i)];
        const bool enabled = pid_enabled(img, b_.first + i);
        const int sv = static_cast<std::int16_t>(word(img, b_.sv, i));
        const std::uint16_t os_word = word(img, b_.os, i);
        const int os = rules_->signed_offset ? static_cast<std::int16_t>(os_word) : int{os_word};

        // Over-temperature guards against a shorted SSR, which does not care whether the point
        // runs PID: every point with a temperature is watched.
        const bool watched = !in.broken || rules_->broken_counts_over;
        p.over_scans =
            watched && in.pv >= over_limit ? std::min(p.over_scans + 1, kOverTemperatureScans) : 0;
        p.over = p.over_scans >= kOverTemperatureScans;

        bool zone = false;
        if (!enabled || in.broken) {
            // R4012/R4013 bit 0: no PID, output off. A broken sensor: no PV to control on, so
            // the output is off too, and the point is out of zone (alarm).
            p.reset_control();
            set_y(img, i, false);
            set_word(img, b_.out, i, 0);
            if (enabled) alarm = true;
        } else {
            if (solve) solve_point(img, i, p, in.pv, sv);
            set_word(img, b_.out, i, p.output);
            if (new_cycle) {
                p.on = std::chrono::duration_cast<engine::Duration>(pwm_ * p.output) / full;
            }
            // ON for OR/full scale of the cycle, to the nearest scan: a scan holds its Y for dt.
            set_y(img, i, (ctx.now - cycle_start_) + ctx.dt / 2 < p.on);

            zone = in.pv >= sv - os && in.pv <= sv + os;
            if (!zone && p.output * 100 >= open_percent * full) {
                if (!p.high_since) p.high_since = ctx.now;
                p.open = ctx.now - *p.high_since >= open_time;
            } else {
                p.high_since.reset();
                p.open = false;
            }
            alarm = alarm || !zone;
        }
        const std::uint32_t bit = 1u << i;
        if (zone) in_zone |= bit;
        if (p.over) over_bits |= bit;
        if (p.open) open_bits |= bit;
        if (p.over || p.open) warn |= bit;
        alarm = alarm || p.over || p.open;
    }
    const Device& s = b_.status;
    set_word(img, s, 0, static_cast<std::uint16_t>(in_zone & 0xFFFF));
    set_word(img, s, 1, static_cast<std::uint16_t>(in_zone >> 16));
    set_word(img, s, 2, static_cast<std::uint16_t>(warn & 0xFFFF));
    set_word(img, s, 3, static_cast<std::uint16_t>(warn >> 16));
    // The state lives here; these words only show it (timing in effect, the warnings' causes).
    set_word(img, s, 4, timing_word());
    set_word(img, s, 5, static_cast<std::uint16_t>(over_bits & 0xFFFF));
    set_word(img, s, 6, static_cast<std::uint16_t>(over_bits >> 16));
    set_word(img, s, 7, static_cast<std::uint16_t>(open_bits & 0xFFFF));
    set_word(img, s, 8, static_cast<std::uint16_t>(open_bits >> 16));
    return alarm;
}

// The positional PID law (FBs manual §21.7, FB manual FUN73): E scaled by the family's gain,
// output in counts of 0…full scale.
void TemperatureLoop::solve_point(const image::Image& img, int i, Point& p, int pv, int sv) const {
    const double full = rules_->full_scale;
    const int ceiling = rules_->gain_ceiling;
    const double kc = std::clamp<int>(word(img, b_.pr, i), 1, ceiling);
    const double ki = std::min<int>(word(img, b_.ir, i), ceiling);
    const double td = std::min<int>(word(img, b_.dr, i), ceiling);
    const double ts = static_cast<double>(ts_.count());
    const double e = (heating_ ? sv - pv : pv - sv) * gain_;
    const double prop = kc * e;  // reaches full scale at the proportional band
    double deriv = 0.0;
    if (p.solved) {
        // Against the change of PV, in the direction that reduces the error.
        const double towards = (heating_ ? pv - p.pv_prev : p.pv_prev - pv) * gain_;
        deriv = -kc * (td / 100.0 * 60.0) * towards / ts;
    }
    p.pv_prev = pv;
    p.solved = true;
    // FBs Md 0 (modified minimum overshoot): integrate only inside the proportional band.
    if (!band_only_ || std::abs(prop) < full) {
        const double step = kc * (ki / 100.0) * (ts / 60.0) * e;
        double next = p.integral + step;
        // No wind-up: integrating never pushes the output further past 0 or full scale.
        if (step > 0) next = std::min(next, std::max(p.integral, full - prop - deriv));
        if (step < 0) next = std::max(next, std::min(p.integral, -prop - deriv));
        p.integral = std::clamp(next, 0.0, full);
    }
    const double m = std::clamp(prop + p.integral + deriv, 0.0, full);
    p.output = static_cast<std::uint16_t>(std::lround(m));
}

}  // namespace plcemu::profiles::fatek
