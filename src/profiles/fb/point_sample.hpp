#pragma once
// One sample of an FB temperature point, as TP4, TSTC and TPSNS take it: the emulated module's
// raw count, R3968+p, the reading with R4015's average, the broken-sensor rule and R4010/R4011
// (FB manual FUN72/FUN73 and FUN85; docs/profile-fb.md, "Conversion").

#include "plcemu/engine/sensors.hpp"
#include "plcemu/image/image.hpp"
#include "profiles/fb/points.hpp"

namespace plcemu::profiles::fb {

/// The emulated module's raw count of point `point` for a sensed sample (`sensor` a Tp code,
/// `pl` a range): full scale for a broken sensor, else §"Conversion"'s count.
int module_raw(
    const image::Image& img, int sensor, int pl, int point, const engine::SensorSample& s) noexcept;

/// Samples point `point`: writes its raw value into R3968+point, updates `pt` (the average's
/// samples, broken, read once) and returns the reading in the display unit (0 when R4010/R4011
/// say the sensor is not installed).
int sample_point(image::Image& img,
                 int sensor,
                 int pl,
                 int point,
                 Point& pt,
                 const engine::SensorSample& s) noexcept;

}  // namespace plcemu::profiles::fb
