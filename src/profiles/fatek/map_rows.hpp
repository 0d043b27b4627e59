#pragma once
// The fixed rows of FATEK's Modbus slave table (FBs manual 13-50/51), which every FATEK family
// serves, and its read-only devices.

#include <vector>

#include "plcemu/image/area.hpp"
#include "plcemu/modbus/address_map.hpp"

namespace plcemu::profiles::fatek {

/// Y, X, M, S, T, C status; R0–R4167, R5000–R5998, D0–D2998, T and C current values.
std::vector<modbus::MapRow> map_rows();
/// X, IR R3840–R3903, M1920–M1927 and R4136–R4138.
std::vector<image::Range> read_only();

}  // namespace plcemu::profiles::fatek
