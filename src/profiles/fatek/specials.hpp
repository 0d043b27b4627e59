#pragma once
// The special relays and registers a FATEK PLC keeps each scan (FBs manual, special relay and
// register tables; docs/profile-fbs.md, "Scan cycle and special registers"): the clocks, the
// first-scan pulse, RUN, R4049, R4055 (station), R4057 (power-ups), the calendar, the scan times
// and the model code. Each family adds the power-up values of its own special registers.

#include <cstdint>
#include <memory>
#include <utility>
#include <vector>

#include "plcemu/engine/specials.hpp"
#include "plcemu/engine/tags.hpp"

namespace plcemu::profiles::fatek {

/// A special register and the value it takes at every start (SR is not retentive).
using PowerUpValue = std::pair<std::uint32_t, std::uint16_t>;

/// M1920–M1926, R4049, R4055, R4057, R4128–R4134, R4136–R4138 and R4167 = `model_code`; at
/// every start also the registers of `power_up` (R number → value).
std::unique_ptr<engine::Specials> make_specials(std::uint16_t model_code,
                                                std::vector<PowerUpValue> power_up);

/// What the relays and registers make_specials() keeps hold, for the tag export.
engine::Tags special_tags();

}  // namespace plcemu::profiles::fatek
