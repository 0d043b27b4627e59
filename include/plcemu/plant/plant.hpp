#pragma once
// A plant: the simulated process behind a PLC's sensors and actuators
// (docs/simulator-and-plant.md). This is all that the daemon, the simulator-control unit, the tag
// export, the profiles and a reload know of it; a model (today the thermal plant,
// thermal_plant.hpp) implements it under src/plant/, and make_plant() is the one place that chooses
// the model.
//
// Plant time is the engine's simulated time: nothing here reads a clock.

#include <array>
#include <cstdint>
#include <memory>

#include "plcemu/engine/declarations.hpp"
#include "plcemu/engine/engine.hpp"
#include "plcemu/engine/sensors.hpp"
#include "plcemu/image/area.hpp"
#include "plcemu/plant/channel.hpp"

namespace plcemu::plant {

/// Channels of the plant: as many as a temperature measurement can number.
inline constexpr int kChannels = 32;

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

/// The default drives of a built program: channel c is driven by the first output the program
/// declares as c's actuator, else by nothing.
std::array<Drive, kChannels> drives_of(const engine::Declarations& program);

/// What a reload carries from the running plant into the new one, per channel: the heaters and
/// their loads do not cool down because the PLC was reconfigured.
struct ChannelState {
    double process_c = 25.0;  ///< the process value (true temperature), °C
    double reading_c = 25.0;  ///< the last value the sensor gave, °C
};
/// The state of every channel.
using PlantState = std::array<ChannelState, kChannels>;

/// A plant: an engine subsystem (advanced before the program, fed the outputs after it) and the
/// source of the measurement subsystems' samples. Channels out of 0…kChannels−1 read as nothing
/// and ignore writes.
class Plant : public engine::Subsystem, public engine::SensorSource {
public:
    // Sensors: engine::SensorSource::sense() is what the measuring modules see (noise, faults).

    /// Process value of a channel as it is, °C (no noise, no sensor fault).
    virtual double true_temperature(int channel) const noexcept = 0;
    /// Sets a channel's process value (test set-up).
    virtual void set_temperature(int channel, double celsius) noexcept = 0;

    // Actuators.

    /// Power actually applied (after faults), mean over the last 8 s, 0–1.
    virtual double heater_power(int channel) const noexcept = 0;
    /// Power the last scan's outputs apply now (after faults), 0–1.
    virtual double drive_now(int channel) const noexcept = 0;

    // Faults (docs/simulator-and-plant.md, "Thermal plant"): set and cleared per channel.

    /// Fault switches of a channel.
    virtual Faults faults(int channel) const noexcept = 0;
    /// Sets the fault switches of a channel (run time; takes effect at the next scan).
    virtual void set_faults(int channel, const Faults& f) noexcept = 0;

    // Parameters a user may change at run time.

    /// Process parameters of a channel.
    virtual const ChannelParams& params(int channel) const noexcept = 0;
    /// Sets the process parameters of a channel (clamped to the model's ranges); the process
    /// value itself is kept.
    virtual void set_params(int channel, const ChannelParams& p) noexcept = 0;

    // A reload.

    /// What a reload carries over.
    virtual PlantState state() const noexcept = 0;
    /// Takes over what the running plant carried (a reload; the new plant is not yet scanned).
    virtual void restore(const PlantState& state) noexcept = 0;
};

/// The plant `setup` describes (today the thermal plant, the one model).
std::unique_ptr<Plant> make_plant(const PlantSetup& setup);

}  // namespace plcemu::plant
