#pragma once
// The FBs special relays and registers the PLC keeps each scan (FBs manual, special relay and
// register tables; docs/profile-fbs.md, "Scan cycle and special registers").

#include <cstdint>
#include <memory>

#include "plcemu/engine/specials.hpp"
#include "plcemu/engine/tags.hpp"

namespace plcemu::profiles::fbs {

/// M1920–M1926, R4005–R4013 power-up values, R4049, R4055 (station), R4057 (power-ups),
/// R4128–R4134 (calendar), R4136–R4138 (scan time), R4167 (model code).
std::unique_ptr<engine::Specials> make_specials(std::uint16_t model_code);

/// What the special relays and registers hold, for the tag export.
engine::Tags special_tags();

}  // namespace plcemu::profiles::fbs
