#include "plcemu/plant/thermal_plant.hpp"

#include <algorithm>
#include <bit>
#include <cctype>
#include <cmath>
#include <numbers>
#include <string>

namespace plcemu::plant {

namespace {

constexpr std::int64_t kNsPerS = 1'000'000'000;
// Heater power is shown as the mean over this window: a whole number of PWM cycles for the
// 1, 2, 4 and 8 s cycles of R4005, so the value does not ripple with the PWM.
constexpr std::int64_t kPowerWindowNs = 8 * kNsPerS;
std::int64_t to_ns(double seconds) {
    return static_cast<std::int64_t>(std::llround(seconds * 1e9));
}

ChannelParams clamp_params(ChannelParams p) {
    // Ranges of the config loader, so a run-time write cannot make the model meaningless.
    p.ambient_c = std::clamp(p.ambient_c, -200.0, 1000.0);
    p.k_c = std::clamp(p.k_c, 0.0, 3000.0);
    p.tau_s = std::clamp(p.tau_s, 0.1, 100000.0);
    p.dead_time_s = std::clamp(p.dead_time_s, 0.0, 3600.0);
    p.noise_c = std::clamp(p.noise_c, 0.0, 100.0);
    p.lead_ohm = std::clamp(p.lead_ohm, 0.0, 100.0);
    return p;
}

// splitmix64: a counter-based generator, so sample n of channel c is the same in every run.
std::uint64_t mix(std::uint64_t x) {
    x += 0x9E3779B97F4A7C15ULL;
    x = (x ^ (x >> 30)) * 0xBF58476D1CE4E5B9ULL;
    x = (x ^ (x >> 27)) * 0x94D049BB133111EBULL;
    return x ^ (x >> 31);
}

double unit_interval(std::uint64_t x) {
    // 53 random bits in (0, 1].
    return (static_cast<double>(x >> 11) + 1.0) / 9007199254740992.0;
}

}  // namespace

// ---------------------------------------------------------------------------------------------

void History::add(std::int64_t t0, std::int64_t t1, double value) noexcept {
    if (t1 <= t0) return;
    if (size() == 0 || pts_.back().t != t0) {
        // First record, or a gap (the signal was 0 in it).
        pts_.push_back({t0, size() == 0 ? 0.0 : pts_.back().c});
        extend_ = false;
    }
    const double inc = value * static_cast<double>(t1 - t0);
    if (extend_ && value == last_) {
        pts_.back().t = t1;
        pts_.back().c += inc;
    } else {
        pts_.push_back({t1, pts_.back().c + inc});
        last_ = value;
        extend_ = true;
    }
    // A signal that changes every scan over a very long dead time: keep every other point (the
    // integral stays exact at the points kept; the memory stays bounded).
    constexpr std::size_t kMaxPoints = 1u << 18;
    if (size() > kMaxPoints) {
        const Point last = pts_.back();
        std::size_t n = 0;
        for (std::size_t i = head_; i < pts_.size(); i += 2) pts_[n++] = pts_[i];
        if (pts_[n - 1].t != last.t) pts_[n++] = last;
        pts_.resize(n);
        head_ = 0;
        extend_ = false;
    }
}

double History::at(std::int64_t t) const noexcept {
    const Point& first = front();
    if (t <= first.t) return first.c - before_ * static_cast<double>(first.t - t);
    if (t >= pts_.back().t) return pts_.back().c;  // nothing recorded yet past the end
    // The first point after t. Queries come just after the forgotten part (the dead-time line
    // is asked about t − θ right after forget_before(t − θ)), so a scan from the front beats a
    // binary search.
    auto it = pts_.begin() + static_cast<std::ptrdiff_t>(head_) + 1;
    while (it->t <= t) ++it;
    const Point& b = *it;
    const Point& a = *(it - 1);
    return a.c + (b.c - a.c) * static_cast<double>(t - a.t) / static_cast<double>(b.t - a.t);
}

double History::mean(std::int64_t t0, std::int64_t t1) const noexcept {
    if (t1 <= t0) return 0.0;
    if (size() == 0) return before_;
    return (at(t1) - at(t0)) / static_cast<double>(t1 - t0);
}

void History::forget_before(std::int64_t t) noexcept {
    while (size() >= 2 && pts_[head_ + 1].t <= t) {
        const Point& a = pts_[head_];
        const Point& b = pts_[head_ + 1];
        before_ = (b.c - a.c) / static_cast<double>(b.t - a.t);
        ++head_;
    }
    // Drop the forgotten prefix once it is half the vector: each point is moved at most once
    // per point forgotten, and the capacity is kept for the points to come.
    if (head_ > 0 && 2 * head_ >= pts_.size()) {
        pts_.erase(pts_.begin(), pts_.begin() + static_cast<std::ptrdiff_t>(head_));
        head_ = 0;
    }
}

// ---------------------------------------------------------------------------------------------

ThermalPlant::ThermalPlant(const PlantSetup& setup)
    : seed_(setup.seed) {
    for (std::size_t i = 0; i < ch_.size(); ++i) {
        const ChannelSetup& cs = setup.channels[i];
        Channel& c = ch_[i];
        c.p = clamp_params(cs.params);
        c.faults = cs.faults;
        c.drive = cs.drive;
        c.t = c.p.ambient_c;
        c.last = c.t;
        if (c.drive.kind != Drive::Kind::None) driven_ |= 1u << i;
    }
}

double ThermalPlant::read_drive(const image::Image& img, const Channel& c) const noexcept {
    const auto& d = c.drive.device;
    if (c.drive.kind == Drive::Kind::None || d.index >= img.layout().size_of(d.area)) return 0.0;
    if (c.drive.kind == Drive::Kind::Output) return img.bit(d.area, d.index) ? 1.0 : 0.0;
    // A signed word: a PID output below 0 is no power, not nearly full power.
    const double v = static_cast<std::int16_t>(img.word(d.area, d.index));
    return std::clamp(v / c.drive.full_scale, 0.0, 1.0);
}

bool ThermalPlant::advance(Channel& c, std::int64_t t0, std::int64_t t1) noexcept {
    // Faults act on the power actually applied: open = no power, shorted = full power.
    const double u = c.faults.heater_open ? 0.0 : (c.faults.heater_shorted ? 1.0 : c.u);
    const std::int64_t theta = to_ns(c.p.dead_time_s);
    // At rest (no power now or within the dead time, at ambient): nothing would change. The
    // histories then keep a gap, which they read as zero power.
    if (u == 0.0 && c.powered_until <= t0 - theta && c.t == c.p.ambient_c) return false;
    if (u != 0.0) c.powered_until = t1;
    c.delay.add(t0, t1, u);
    c.window.add(t0, t1, u);
    const double ud = c.delay.mean(t0 - theta, t1 - theta);
    const double rise = (c.p.cooling ? -c.p.k_c : c.p.k_c) * ud;
    const double target = c.p.ambient_c + rise;
    // Exact solution of dT/dt = (target − T)/τ over the step: stable for any step length.
    const double dt = static_cast<double>(t1 - t0) / 1e9;
    if (dt != c.decay_dt || c.p.tau_s != c.decay_tau) {
        c.decay_dt = dt;
        c.decay_tau = c.p.tau_s;
        c.decay = std::exp(-dt / c.p.tau_s);
    }
    c.t = target + (c.t - target) * c.decay;
    // Settled back to ambient with no power: snap, so the channel can rest (1e-6 °C is far
    // below the 0.1° resolution of any reading).
    if (ud == 0.0 && std::abs(c.t - target) < 1e-6) c.t = target;
    c.delay.forget_before(t1 - theta);
    c.window.forget_before(t1 - kPowerWindowNs);
    return true;
}

void ThermalPlant::inputs(engine::ScanContext& ctx) noexcept {
    const std::int64_t now = ctx.now.count();
    if (!started_) {
        started_ = true;
        now_ns_ = now;
        return;
    }
    if (now <= now_ns_) return;
    for (std::uint32_t m = awake_; m != 0; m &= m - 1) {
        const auto i = std::countr_zero(m);
        if (!advance(ch_[static_cast<std::size_t>(i)], now_ns_, now)) awake_ &= ~(1u << i);
    }
    now_ns_ = now;
}

void ThermalPlant::outputs(engine::ScanContext& ctx) noexcept {
    for (std::uint32_t m = driven_ | released_; m != 0; m &= m - 1) {
        const auto i = std::countr_zero(m);
        Channel& c = ch_[static_cast<std::size_t>(i)];
        c.u = read_drive(ctx.image, c);
        if (c.u != 0.0) wake(i);
    }
    released_ = 0;
}

double ThermalPlant::noise(int channel, std::uint64_t n) const noexcept {
    const std::uint64_t base = mix(seed_ ^ mix(static_cast<std::uint64_t>(channel) << 40 ^ n));
    const double u1 = unit_interval(mix(base));
    const double u2 = unit_interval(mix(base + 1));
    // Box–Muller: a standard normal deviate.
    return std::sqrt(-2.0 * std::log(u1)) * std::cos(2.0 * std::numbers::pi * u2);
}

engine::SensorSample ThermalPlant::sense(int channel) noexcept {
    if (!valid(channel)) return {true, 0.0};
    Channel& c = ch_[static_cast<std::size_t>(channel)];
    if (c.faults.sensor_broken) return {true, 0.0, c.p.lead_ohm};
    if (c.faults.reading_frozen) {
        if (!c.held) c.held = c.last;
        return {false, *c.held, c.p.lead_ohm};
    }
    c.held.reset();
    double v = c.t;
    if (c.p.noise_c > 0.0) v += c.p.noise_c * noise(channel, c.samples++);
    c.last = v;
    return {false, v, c.p.lead_ohm};
}

double ThermalPlant::true_temperature(int channel) const noexcept {
    return valid(channel) ? ch_[static_cast<std::size_t>(channel)].t : 0.0;
}

double ThermalPlant::heater_power(int channel) const noexcept {
    if (!valid(channel)) return 0.0;
    const Channel& c = ch_[static_cast<std::size_t>(channel)];
    const std::int64_t from = std::max<std::int64_t>(0, now_ns_ - kPowerWindowNs);
    if (now_ns_ <= from) return drive_now(channel);
    return c.window.mean(from, now_ns_);
}

double ThermalPlant::drive_now(int channel) const noexcept {
    if (!valid(channel)) return 0.0;
    const Channel& c = ch_[static_cast<std::size_t>(channel)];
    return c.faults.heater_open ? 0.0 : (c.faults.heater_shorted ? 1.0 : c.u);
}

Faults ThermalPlant::faults(int channel) const noexcept {
    return valid(channel) ? ch_[static_cast<std::size_t>(channel)].faults : Faults{};
}

void ThermalPlant::set_faults(int channel, const Faults& f) noexcept {
    if (!valid(channel)) return;
    ch_[static_cast<std::size_t>(channel)].faults = f;
    wake(channel);
}

const ChannelParams& ThermalPlant::params(int channel) const noexcept {
    return ch_[static_cast<std::size_t>(std::clamp(channel, 0, kChannels - 1))].p;
}

void ThermalPlant::set_params(int channel, const ChannelParams& p) noexcept {
    if (!valid(channel)) return;
    Channel& c = ch_[static_cast<std::size_t>(channel)];
    const ChannelParams np = clamp_params(p);
    // A longer dead time looks further back than was kept: that stretch counts as the power
    // applied when it was forgotten (History::mean).
    c.p = np;
    wake(channel);
}

void ThermalPlant::set_temperature(int channel, double celsius) noexcept {
    if (!valid(channel)) return;
    ch_[static_cast<std::size_t>(channel)].t = celsius;
    wake(channel);
}

PlantState ThermalPlant::state() const noexcept {
    PlantState s;
    for (std::size_t i = 0; i < ch_.size(); ++i) s[i] = {ch_[i].t, ch_[i].last};
    return s;
}

void ThermalPlant::restore(const PlantState& state) noexcept {
    for (std::size_t i = 0; i < ch_.size(); ++i) {
        ch_[i].t = state[i].process_c;
        ch_[i].last = state[i].reading_c;
    }
    awake_ = ~0u;
}

const Drive& ThermalPlant::drive(int channel) const noexcept {
    return ch_[static_cast<std::size_t>(std::clamp(channel, 0, kChannels - 1))].drive;
}

void ThermalPlant::set_drive(int channel, const Drive& d) noexcept {
    if (!valid(channel)) return;
    ch_[static_cast<std::size_t>(channel)].drive = d;
    const std::uint32_t bit = 1u << channel;
    if (d.kind == Drive::Kind::None) {
        // Its latched drive goes to 0 at the next outputs(), as every undriven channel's.
        if (driven_ & bit) released_ |= bit;
        driven_ &= ~bit;
    } else {
        driven_ |= bit;
        released_ &= ~bit;
    }
}

}  // namespace plcemu::plant
