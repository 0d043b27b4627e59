#pragma once
// A plant channel's process parameters and fault switches (docs/simulator-and-plant.md): the
// plant's own values, which the config loader reads the `plant:` section into (the config turns
// into the values each part needs, DESIGN's direction of dependencies), and which the simulator
// unit and the console change at run time. Plain values: nothing here includes the engine.

namespace plcemu::plant {

/// The fault switches of a channel.
struct Faults {
    bool sensor_broken = false;   ///< reading 32767, abnormal bit
    bool heater_open = false;     ///< u forced to 0
    bool heater_shorted = false;  ///< u forced to 1
    bool reading_frozen = false;  ///< reading stops changing

    bool operator==(const Faults&) const = default;
};

/// Process parameters of one channel, in engineering units: what `plant:` sets and a user may
/// change at run time (the simulator-control unit).
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

}  // namespace plcemu::plant
