#pragma once
// The FB special relays and registers the PLC keeps each scan: the FATEK ones, with the FB's
// temperature registers R4004–R4023 set to their defaults at every start (FB manual FUN72/FUN73,
// FUN86; docs/profile-fb.md, "Special registers").

#include <cstdint>
#include <memory>

#include "plcemu/engine/specials.hpp"
#include "plcemu/engine/tags.hpp"

namespace plcemu::profiles::fb {

/// The FATEK specials (profiles/fatek/specials.hpp) with the FB power-up values of R4004–R4023.
std::unique_ptr<engine::Specials> make_specials(std::uint16_t model_code);

/// What the special relays and registers hold, for the tag export.
engine::Tags special_tags();

}  // namespace plcemu::profiles::fb
