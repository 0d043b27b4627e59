#pragma once
// The VB Modbus slave map.

#include "plcemu/modbus/address_map.hpp"

namespace plcemu::profiles::vb {

/// The VB default map: the FX3U MODBUS default allocation (FX3U MODBUS manual (JY997D26201)
/// §9.3) with the VB's devices, timer and counter values where the FBs map has them.
const modbus::AddressMap& map();

}  // namespace plcemu::profiles::vb
