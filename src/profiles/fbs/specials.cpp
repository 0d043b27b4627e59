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

}  // namespace plcemu::profiles::fbs
