#pragma once
// How Ladder Master writes a VB program as an instruction list (the FX family's mnemonics;
// docs/program-language.md, "vb").

#include "plcemu/instructions/listing.hpp"

namespace plcemu::profiles::vb {

/// The VB's instruction-list statements and the applied instructions this profile has.
const instructions::Dialect& listing_dialect();

}  // namespace plcemu::profiles::vb
