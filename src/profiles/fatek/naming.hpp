#pragma once
// How the FATEK families (FBs, FB) write their devices: X, Y, M, S, T, C, R, D and the TMR/CTR
// current values, all numbered in decimal, C200–C255 32-bit.

#include "plcemu/image/naming.hpp"

namespace plcemu::profiles::fatek {

/// The FATEK device spelling (FBs manual, device table; the FB manual uses the same names).
image::Naming make_naming();

}  // namespace plcemu::profiles::fatek
