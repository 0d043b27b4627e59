#pragma once
// The simulated thermal plant (docs/simulator-and-plant.md, "Thermal plant"): one
// first-order-plus-dead-time process per temperature channel, heated (or cooled) by the duty of its
// Y output or by an OR value.
//
// Plant time is the engine's simulated time: nothing here reads a clock. By default, channel c is
// heated by the output a program declares as channel c's actuator (plant::drives_of); a
// `plant.channels.N.drive` names another. docs/simulator-and-plant.md describes the model. Only
// src/plant/ and the model's own tests name this class: the rest of the emulator sees a Plant.

#include <array>
#include <cstdint>
#include <optional>
#include <vector>

#include "plcemu/plant/plant.hpp"

namespace plcemu::plant {

/// A piecewise-constant signal over simulated time (nanoseconds), kept as its running integral
/// at the points where it changed: the dead-time line and the heater-power window of a channel.
/// Means over any interval are exact, whatever the scan period, and a PWM output costs two
/// points per cycle.
class History {
public:
    /// Records that the signal was `value` over [t0, t1) (t0 = the end of the last record).
    void add(std::int64_t t0, std::int64_t t1, double value) noexcept;
    /// The mean of the signal over [t0, t1). Times before anything was recorded count as 0;
    /// times already forgotten as the value the signal had when it was forgotten.
    double mean(std::int64_t t0, std::int64_t t1) const noexcept;
    /// Forgets what lies wholly before `t`.
    void forget_before(std::int64_t t) noexcept;
    /// Points kept.
    std::size_t size() const { return pts_.size() - head_; }

private:
    struct Point {
        std::int64_t t;  // time
        double c;        // integral of the signal up to t, value·ns
    };
    double at(std::int64_t t) const noexcept;  // running integral at t
    const Point& front() const { return pts_[head_]; }

    // The points kept are pts_[head_..]: forgetting moves head_, and the forgotten prefix is
    // dropped once it is half the vector. Nothing is allocated until the first record, so an
    // idle channel costs no heap (a plant has 64 of these).
    std::vector<Point> pts_;
    std::size_t head_ = 0;
    double last_ = 0.0;    // value of the last segment
    bool extend_ = false;  // the last segment may be extended
    double before_ = 0.0;  // value before the first point
};

/// The thermal plant: an engine subsystem with up to 32 channels.
///
/// Each scan, `inputs()` advances every channel from the previous scan to this one with the
/// drive that was latched by the previous scan's `outputs()` (a Y bit holds for the whole scan
/// interval, which is what makes PWM duty the average power); `outputs()` latches the drives the
/// program has just written. Per channel: dT/dt = (±K·u(t−θ) − (T − T_amb)) / τ, integrated
/// exactly for a drive that is constant over the step, so any scan period is stable.
class ThermalPlant final : public Plant {
public:
    /// A plant as `setup` says.
    explicit ThermalPlant(const PlantSetup& setup);

    /// Advances the processes to this scan's time.
    void inputs(engine::ScanContext& ctx) noexcept override;
    /// Latches the drives the program wrote.
    void outputs(engine::ScanContext& ctx) noexcept override;
    /// Samples a sensor (noise, faults): see SensorSource.
    engine::SensorSample sense(int channel) noexcept override;

    double true_temperature(int channel) const noexcept override;
    void set_temperature(int channel, double celsius) noexcept override;
    double heater_power(int channel) const noexcept override;
    double drive_now(int channel) const noexcept override;
    Faults faults(int channel) const noexcept override;
    void set_faults(int channel, const Faults& f) noexcept override;
    const ChannelParams& params(int channel) const noexcept override;
    /// Values out of range are clamped: τ ≥ 0.1 s, θ 0–3600 s, K 0–3000, noise ≥ 0.
    void set_params(int channel, const ChannelParams& p) noexcept override;
    /// The process temperatures and the last readings.
    PlantState state() const noexcept override;
    void restore(const PlantState& state) noexcept override;

    /// What drives a channel.
    const Drive& drive(int channel) const noexcept;
    /// Changes what drives a channel.
    void set_drive(int channel, const Drive& d) noexcept;
    /// Simulated time the plant has reached.
    engine::Duration now() const { return engine::Duration{now_ns_}; }

private:
    // The fields outputs() and a resting channel's check read come first, in one cache line:
    // 5,000 PLCs scanning every 10 ms touch a plant 500,000 times a second, each in a cold cache.
    struct Channel {
        Drive drive;
        double u = 0.0;   // drive latched by the last outputs(), after faults
        double t = 25.0;  // true temperature, °C
        std::int64_t powered_until = INT64_MIN;  // end of the last step with power applied
        Faults faults;
        ChannelParams p;
        History delay;               // applied power, for the dead time
        History window;              // applied power, for heater_power()
        std::optional<double> held;  // reading kept while the reading is frozen
        double last = 25.0;          // last sensed value
        std::uint64_t samples = 0;   // sensor samples taken, for the noise sequence
        double decay_dt = -1.0;      // step length (s) and τ the cached decay was computed for
        double decay_tau = -1.0;
        double decay = 1.0;  // exp(−dt/τ)
    };
    static_assert(kChannels <= 32, "the channel masks are 32 bits");

    static bool valid(int channel) { return channel >= 0 && channel < kChannels; }
    double read_drive(const image::Image& img, const Channel& c) const noexcept;
    /// Advances one channel; false when it is at rest (nothing changed, nor will until a drive,
    /// a fault, a temperature or a parameter does).
    bool advance(Channel& c, std::int64_t t0, std::int64_t t1) noexcept;
    void wake(int channel) noexcept { awake_ |= 1u << channel; }
    double noise(int channel, std::uint64_t n) const noexcept;

    std::array<Channel, kChannels> ch_;
    // Only what can change is visited each scan, which is what lets thousands of PLCs idle
    // cheaply; a channel left out behaves exactly as the full loop would (advance() returns at
    // once at rest, and an undriven channel's drive is 0).
    std::uint32_t awake_ = ~0u;   // channels inputs() advances: the others are at rest
    std::uint32_t driven_ = 0;    // channels with a drive, which outputs() reads
    std::uint32_t released_ = 0;  // channels whose drive was removed: outputs() zeroes them once
    std::uint64_t seed_;
    std::int64_t now_ns_ = 0;
    bool started_ = false;
};

}  // namespace plcemu::plant
