#pragma once
// The FBs Modbus slave map.

#include "plcemu/engine/tags.hpp"
#include "plcemu/modbus/address_map.hpp"

namespace plcemu::profiles::fbs {

/// The FBs map of the manual's table (13-50/51), with the R3968–R3980 user maps held in the
/// image.
const modbus::AddressMap& map();

/// What the user-map registers R3968–R3980 hold, for the tag export.
engine::Tags map_tags();

}  // namespace plcemu::profiles::fbs
