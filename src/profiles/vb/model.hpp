#pragma once
// VIGOR model names: "VB2-32M", "VH-40MR" (docs/profile-vb.md, "Identity").

#include <string_view>

namespace plcemu::profiles::vb {

/// True for a name of the form V[BH][0-9]?-[0-9]+M[A-Z]*: VB or VH, an optional series digit,
/// the I/O points, M for a main unit and the output type letters.
bool valid_model(std::string_view model);

}  // namespace plcemu::profiles::vb
