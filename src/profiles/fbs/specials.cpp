#include "profiles/fbs/specials.hpp"

#include "profiles/fatek/specials.hpp"
#include "profiles/fbs/special_registers.hpp"

namespace plcemu::profiles::fbs {

std::unique_ptr<engine::Specials> make_specials(std::uint16_t model_code) {
    namespace sp = special;
    // FBs manual §21.7: defaults of R4005–R4008, R4010–R4013 at start.
    return fatek::make_specials(model_code, {{sp::kPidTiming, 0x0102},
                                             {sp::kHeaterOpenPercent, 90},
                                             {sp::kHeaterOpenSeconds, 600},
                                             {sp::kOverTemperature, 3500},
                                             {sp::kSensorInstalled, 0xFFFF},
                                             {sp::kSensorInstalled + 1, 0xFFFF},
                                             {sp::kPidEnable, 0xFFFF},
                                             {sp::kPidEnable + 1, 0xFFFF}});
}

engine::Tags special_tags() {
    using engine::Number;
    using image::Area;
    namespace sp = special;
    engine::Tags t = fatek::special_tags();
    const engine::Tags own{
        {{Area::R, sp::kTempMeasureRemap, 1},
         "special register: A55Ah takes the TPCTL PVs from the block R4004 names",
         Number::Unsigned},
        {{Area::R, sp::kTempPvSource, 1},
         "special register: TPCTL PV start (encoded: 10000+n = Rn, 20000+n = Dn)",
         Number::Unsigned},
        {{Area::R, sp::kPidTiming, 1},
         "special register: TPCTL PWM cycle (high byte) and solution interval (low byte) codes",
         Number::Unsigned},
        {{Area::R, sp::kHeaterOpenPercent, 1}, "special register: heater-open detection output, %"},
        {{Area::R, sp::kHeaterOpenSeconds, 1}, "special register: heater-open detection time, s"},
        {{Area::R, sp::kOverTemperature, 1},
         "special register: over-temperature limit, 0.1 degree"},
        {{Area::R, sp::kTempUnit, 1},
         "special register: temperature unit, low byte 0 C, 1 F",
         Number::Unsigned},
        {{Area::R, sp::kSensorInstalled, 2},
         "special register: sensor-installed bits, points 0-15 and 16-31",
         Number::Unsigned},
        {{Area::R, sp::kPidEnable, 2},
         "special register: PID enable bits, points 0-15 and 16-31",
         Number::Unsigned},
        {{Area::R, sp::kTempAverage, 1},
         "special register: temperature moving average, 0-4 = 1, 2, 4, 8, 16 samples",
         Number::Unsigned},
    };
    t.insert(t.end(), own.begin(), own.end());
    return t;
}

}  // namespace plcemu::profiles::fbs
