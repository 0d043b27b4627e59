#include "profiles/fb/point_sample.hpp"

#include "profiles/fb/conversion.hpp"
#include "profiles/fb/special_registers.hpp"

namespace plcemu::profiles::fb {

namespace {
using image::Area;
namespace sp = special;
}  // namespace

int module_raw(const image::Image& img,
               int sensor,
               int pl,
               int point,
               const engine::SensorSample& s) noexcept {
    if (thermocouple(sensor))
        return s.broken ? full_scale_raw(pl) : thermocouple_raw(s.celsius, sensor, pl);
    if (s.broken) return 4095;
    const Factors f = Factors::read(img);
    const int c10 = rtd_celsius10(
        rtd_sample(s.celsius, s.lead_ohm, compensation_ohm(img, point), sensor, pl, f.jis), 1,
        sensor, f);
    return rtd_raw(c10, sensor, pl, f.jis);
}

int sample_point(image::Image& img,
                 int sensor,
                 int pl,
                 int point,
                 Point& pt,
                 const engine::SensorSample& s) noexcept {
    const Factors f = Factors::read(img);
    const int n = averaged_samples(img.word(Area::R, sp::kTempAverage));
    int raw = 0;
    int reading = 0;
    bool broken = false;
    if (thermocouple(sensor)) {
        // FB manual FUN73: the raw value is stored first, then converted.
        raw = module_raw(img, sensor, pl, point, s);
        const int single = thermocouple_display(thermocouple_celsius(raw, 1, sensor, pl, f), f);
        broken = thermocouple_broken(single, pl, f);
        if (broken) {
            pt.clear_samples();  // a broken sample empties the average
            reading = single;
        } else {
            pt.add(raw);
            reading =
                thermocouple_display(thermocouple_celsius(pt.sum(n), pt.used(n), sensor, pl, f), f);
        }
    } else if (s.broken) {
        pt.clear_samples();
        broken = true;
        reading = kRtdBroken;
        raw = 4095;
    } else {
        // RTD: converted first, and the reading converted back into R3968+p last.
        const int s10 =
            rtd_sample(s.celsius, s.lead_ohm, compensation_ohm(img, point), sensor, pl, f.jis);
        const int single_c10 = rtd_celsius10(s10, 1, sensor, f);
        broken = rtd_broken(rtd_display(single_c10, f));
        int c10 = single_c10;
        if (broken) {
            pt.clear_samples();
        } else {
            pt.add(s10);
            c10 = rtd_celsius10(pt.sum(n), pt.used(n), sensor, f);
        }
        reading = rtd_display(c10, f);
        raw = rtd_raw(c10, sensor, pl, f.jis);
    }
    img.set_word(Area::R, sp::kRawReadings + static_cast<std::uint32_t>(point),
                 static_cast<std::uint16_t>(raw));
    // R4010/R4011 bit 0: no check, no warning, the reading is 0.
    const std::uint16_t installed =
        img.word(Area::R, sp::kSensorInstalled + static_cast<std::uint32_t>(point / 16));
    if (((installed >> (point % 16)) & 1u) == 0) {
        reading = 0;
        broken = false;
        pt.clear_samples();
    }
    pt.broken = broken;
    pt.read_once = true;
    return reading;
}

}  // namespace plcemu::profiles::fb
