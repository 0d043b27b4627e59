#pragma once
// The simulated thermal plant (docs/simulator-and-plant.md, "Thermal plant"): one
// first-order-plus-dead-time process per temperature channel, heated (or cooled) by the duty of its
// Y output or by an OR value.
//
// Plant time is the engine's simulated time: nothing here reads a clock. By default, channel c is
// heated by the output a program declares as channel c's actuator (engine/declarations.hpp); a
// `plant.channels.N.drive` names another. docs/simulator-and-plant.md describes the model.

#include <array>
#include <cstdint>
#include <memory>
#include <optional>
#include <vector>

#include "plcemu/engine/declarations.hpp"
#include "plcemu/engine/engine.hpp"
#include "plcemu/engine/sensors.hpp"
#include "plcemu/image/area.hpp"

namespace plcemu::plant {

/// Channels of the plant: as many as a temperature measurement can number.
inline constexpr int kChannels = 32;

/// The fault switches of a channel.
struct Faults {
    bool sensor_broken = false;   ///< reading 32767, abnormal bit
    bool heater_open = false;     ///< u forced to 0
    bool heater_shorted = false;  ///< u forced to 1
    bool reading_frozen = false;  ///< reading stops changing

    bool operator==(const Faults&) const = default;
};

/// Process parameters of one channel, in engineering units.
struct ChannelParams {
    double ambient_c = 25.0;   ///< T_amb, °C
    double k_c = 400.0;        ///< full-power rise K, °C (cooling: full-power fall)
    double tau_s = 120.0;      ///< time constant τ, s (> 0)
    double dead_time_s = 5.0;  ///< dead time θ, s (≥ 0)
    double noise_c = 0.0;      ///< standard deviation of the sensor noise, °C
    bool cooling = false;      ///< the actuator pulls T down instead of up
    double lead_ohm = 0.0;     ///< resistance of an RTD sensor's leads, Ω (0–100)

    bool operator==(const ChannelParams&) const = default;
};

/// What drives a channel's actuator.
struct Drive {
    /// Where u comes from.
    enum class Kind : std::uint8_t {
        None,     ///< nothing: u = 0
        Output,   ///< a Y output: u is the duty of the bit over time (PWM)
        Register  ///< an R/D register: u = value / full_scale (signed), clamped to 0–1
    };
    Kind kind = Kind::None;     ///< the source
    image::Device device;       ///< the Y bit or the R/D word
    double full_scale = 16383;  ///< a register's value for full power (> 0)

    bool operator==(const Drive&) const = default;
};

/// How one channel starts.
struct ChannelSetup {
    ChannelParams params;  ///< process parameters (clamped to the model's ranges)
    Faults faults;         ///< fault switches
    Drive drive;           ///< what drives the actuator
};

/// How the plant starts: the values the daemon takes from `plant:` and the program.
struct PlantSetup {
    std::uint64_t seed = 1;                          ///< noise seed (deterministic)
    std::array<ChannelSetup, kChannels> channels{};  ///< channel c
};

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
class ThermalPlant final : public engine::Subsystem, public engine::SensorSource {
public:
    /// A plant as `setup` says.
    explicit ThermalPlant(const PlantSetup& setup);

    /// The default drives of a built program: channel c is driven by the first output the
    /// program declares as c's actuator, else by nothing.
    static std::array<Drive, kChannels> drives_of(const engine::Declarations& program);

    /// Advances the processes to this scan's time.
    void inputs(engine::ScanContext& ctx) noexcept override;
    /// Latches the drives the program wrote.
    void outputs(engine::ScanContext& ctx) noexcept override;
    /// Samples a sensor (noise, faults): see SensorSource.
    engine::SensorSample sense(int channel) noexcept override;

    /// True temperature of a channel, °C (no noise, no sensor fault).
    double true_temperature(int channel) const noexcept;
    /// Heater power actually applied (after faults), mean over the last 8 s, 0–1.
    double heater_power(int channel) const noexcept;
    /// The drive u latched by the last scan (after faults), 0–1.
    double drive_now(int channel) const noexcept;
    /// Fault switches of a channel.
    Faults faults(int channel) const noexcept;
    /// Sets the fault switches of a channel (run time; takes effect at the next scan).
    void set_faults(int channel, const Faults& f) noexcept;
    /// Process parameters of a channel.
    const ChannelParams& params(int channel) const noexcept;
    /// Sets the process parameters of a channel (values out of range are clamped: τ ≥ 0.1 s,
    /// θ 0–3600 s, K 0–3000, noise ≥ 0). T itself is kept.
    void set_params(int channel, const ChannelParams& p) noexcept;
    /// Sets a channel's true temperature (test set-up).
    void set_temperature(int channel, double celsius) noexcept;
    /// What drives a channel.
    const Drive& drive(int channel) const noexcept;
    /// Changes what drives a channel.
    void set_drive(int channel, const Drive& d) noexcept;
    /// Takes over the process temperatures of `old` (a config reload: the heaters and their
    /// loads do not cool down because the PLC was reconfigured).
    void continue_from(const ThermalPlant& old) noexcept;
    /// Simulated time the plant has reached.
    engine::Duration now() const { return engine::Duration{now_ns_}; }

private:
    struct Channel {
        ChannelParams p;
        Faults faults;
        Drive drive;
        double t = 25.0;             // true temperature, °C
        double u = 0.0;              // drive latched by the last outputs(), after faults
        History delay;               // applied power, for the dead time
        History window;              // applied power, for heater_power()
        std::optional<double> held;  // reading kept while the reading is frozen
        double last = 25.0;          // last sensed value
        std::uint64_t samples = 0;   // sensor samples taken, for the noise sequence
        std::int64_t powered_until = INT64_MIN;  // end of the last step with power applied
        double decay_dt = -1.0;  // step length (s) and τ the cached decay was computed for
        double decay_tau = -1.0;
        double decay = 1.0;  // exp(−dt/τ)
    };

    static bool valid(int channel) { return channel >= 0 && channel < kChannels; }
    double read_drive(const image::Image& img, const Channel& c) const noexcept;
    void advance(Channel& c, std::int64_t t0, std::int64_t t1) noexcept;
    double noise(int channel, std::uint64_t n) const noexcept;

    std::array<Channel, kChannels> ch_;
    std::uint64_t seed_;
    std::int64_t now_ns_ = 0;
    bool started_ = false;
};

}  // namespace plcemu::plant
