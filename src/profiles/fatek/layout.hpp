#pragma once
// The device areas and default retentive ranges of a FATEK PLC (FBs manual, device table;
// docs/profile-fbs.md, "Device areas"), which the FATEK families share but for the size of D.

#include <cstdint>
#include <string_view>

#include "plcemu/image/layout.hpp"

namespace plcemu::profiles::fatek {

/// X0–X255, Y0–Y255, M0–M2001, S0–S999, T0–T255, C0–C255 (C200–C255 32-bit), R0–R8071 (R4168–
/// R4999 never mapped) and D0…D(d_words−1), all of D retentive by default.
image::Layout make_layout(std::uint32_t family, std::string_view name, std::uint32_t d_words);

}  // namespace plcemu::profiles::fatek
