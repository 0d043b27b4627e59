#pragma once
// Where a measurement subsystem takes its samples from: the thermal plant in the daemon, a fake
// in tests. The measurement and the plant meet here, without knowing each other.

namespace plcemu::engine {

/// One sample of a channel's sensor, as the measuring module sees it.
struct SensorSample {
    bool broken = false;   ///< open circuit: no temperature
    double celsius = 0.0;  ///< sensed temperature, °C
    /// Resistance of the sensor's leads, Ω: a module that measures an RTD's resistance sees it
    /// added to the sensor's.
    double lead_ohm = 0.0;
};

/// A source of sensor samples.
class SensorSource {
public:
    virtual ~SensorSource() = default;
    /// Samples channel `channel` (0-based) once; called each time a module converts it.
    virtual SensorSample sense(int channel) noexcept = 0;
};

}  // namespace plcemu::engine
