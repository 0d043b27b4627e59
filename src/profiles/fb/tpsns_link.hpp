#pragma once
// What FUN85 TPSNS tells the FB's FUN86 TPCTLs of its program (FB manual FUN86: "FUN86 must
// incorporate with FUN85 … the FUN85 instruction is for temperature measurement and it must be
// enabled, then, can the FUN86 start working"; docs/profile-fb.md, "FUN86 TPCTL").

#include "plcemu/image/area.hpp"

namespace plcemu::profiles::fb {

/// The program's TPSNS as its TPCTLs see it: filled when it binds, `running` every scan.
struct TpsnsLink {
    int sensor = 0;        ///< its tp: 0 K, 1 J
    int pl = 0;            ///< its pl, 0–3
    image::Device tr;      ///< its first reading: TR + p is point p
    bool running = false;  ///< at its last scan: valid operands and EN 1
};

}  // namespace plcemu::profiles::fb
