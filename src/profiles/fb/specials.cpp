#include "profiles/fb/specials.hpp"

#include "profiles/fatek/specials.hpp"
#include "profiles/fb/special_registers.hpp"

namespace plcemu::profiles::fb {

std::unique_ptr<engine::Specials> make_specials(std::uint16_t model_code) {
    namespace sp = special;
    namespace d = special::defaults;
    // SR is not retentive: every start gives these values, then a program or a master may change
    // them (`init:` presets, applied after, win).
    return fatek::make_specials(model_code, {{sp::kTpsnsInterval, d::kTpsnsInterval},
                                             {sp::kPidTiming, d::kPidTiming},
                                             {sp::kHeaterOpenPercent, d::kHeaterOpenPercent},
                                             {sp::kHeaterOpenSeconds, d::kHeaterOpenSeconds},
                                             {sp::kOverTemperature, d::kOverTemperature},
                                             {sp::kTempUnit, 0},
                                             {sp::kSensorInstalled, 0xFFFF},
                                             {sp::kSensorInstalled + 1, 0xFFFF},
                                             {sp::kPidEnable, 0xFFFF},
                                             {sp::kPidEnable + 1, 0xFFFF},
                                             {sp::kPointInterval, d::kPointInterval},
                                             {sp::kTempAverage, 0},
                                             {sp::kFactorKPositive, d::kFactorKPositive},
                                             {sp::kFactorKNegative, d::kFactorKNegative},
                                             {sp::kFactorJPositive, d::kFactorJPositive},
                                             {sp::kFactorJNegative, d::kFactorJNegative},
                                             {sp::kRtdStandard, d::kRtdStandard},
                                             {sp::kCompensationTable, d::kCompensationTable},
                                             {sp::kFactorPt100, d::kFactorRtd},
                                             {sp::kFactorPt1000, d::kFactorRtd}});
}

engine::Tags special_tags() {
    using engine::Number;
    using image::Area;
    namespace sp = special;
    engine::Tags t = fatek::special_tags();
    const engine::Tags own{
        {{Area::R, sp::kRawReadings, sp::kPoints},
         "special register: raw reading of temperature point 0-31 (0-4095)",
         Number::Unsigned},
        {{Area::R, sp::kTpsnsInterval, 1}, "special register: TPSNS ms between groups of points"},
        {{Area::R, sp::kPidTiming, 1},
         "special register: PID solution interval and PWM cycle codes",
         Number::Unsigned},
        {{Area::R, sp::kHeaterOpenPercent, 1}, "special register: heater-open detection output, %"},
        {{Area::R, sp::kHeaterOpenSeconds, 1}, "special register: heater-open detection time, s"},
        {{Area::R, sp::kOverTemperature, 1}, "special register: over-temperature limit, degree"},
        {{Area::R, sp::kTempUnit, 1},
         "special register: temperature unit, 0 C, 1 F",
         Number::Unsigned},
        {{Area::R, sp::kSensorInstalled, 2},
         "special register: sensor-installed bits, points 0-15 and 16-31",
         Number::Unsigned},
        {{Area::R, sp::kPidEnable, 2},
         "special register: PID enable bits, points 0-15 and 16-31",
         Number::Unsigned},
        {{Area::R, sp::kPointInterval, 1}, "special register: TP4/TSTC ms between points"},
        {{Area::R, sp::kTempAverage, 1},
         "special register: temperature moving average, 0-4 = 1, 2, 4, 8, 16 samples",
         Number::Unsigned},
        {{Area::R, sp::kFactorKPositive, 2},
         "special register: K thermocouple factor, positive and negative temperatures"},
        {{Area::R, sp::kFactorJPositive, 2},
         "special register: J thermocouple factor, positive and negative temperatures"},
        {{Area::R, sp::kRtdStandard, 1},
         "special register: RTD standard (high byte 0 DIN, 1 JIS) and compensation table area",
         Number::Unsigned},
        {{Area::R, sp::kCompensationTable, 1},
         "special register: line-resistance compensation table start",
         Number::Unsigned},
        {{Area::R, sp::kFactorPt100, 2},
         "special register: Pt100 and Pt1000 linearity factors (x/1024)"},
    };
    t.insert(t.end(), own.begin(), own.end());
    return t;
}

}  // namespace plcemu::profiles::fb
