#pragma once
// The FBs special relays and registers the PLC keeps each scan (FBs manual, special relay and
// register tables; docs/profile-fbs.md, "Scan cycle and special registers").

#include <cstdint>
#include <memory>

#include "plcemu/engine/specials.hpp"
#include "plcemu/engine/tags.hpp"

namespace plcemu::profiles::fbs {

/// The FATEK specials (profiles/fatek/specials.hpp) with the FBs power-up values of R4005–R4013.
std::unique_ptr<engine::Specials> make_specials(std::uint16_t model_code);

/// What the special relays and registers hold, for the tag export.
engine::Tags special_tags();

}  // namespace plcemu::profiles::fbs
