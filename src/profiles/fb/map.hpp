#pragma once
// The FB Modbus slave map: FATEK's table without the R3968 user remap (docs/profile-fb.md,
// "Modbus map").

#include "plcemu/modbus/address_map.hpp"

namespace plcemu::profiles::fb {

/// FATEK's fixed table; R3968–R3999 are plain holding registers (the raw temperature readings),
/// and FC02/FC04 are not served.
const modbus::AddressMap& map();

}  // namespace plcemu::profiles::fb
