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

}  // namespace plcemu::profiles::fb
