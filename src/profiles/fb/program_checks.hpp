#pragma once
// Rules on the FB temperature instructions a program holds together (FB manual FUN73/FUN85/
// FUN86; docs/profile-fb.md, "FUN85 TPSNS"): the FB-4AJ(K)xx is used alone, so a program with a
// TPSNS has no TP4 or TSTC and one TPSNS at most; a TPCTL needs the TPSNS.

#include "plcemu/config/config.hpp"

namespace plcemu::profiles::fb {

/// Throws config::ConfigError at the later of two entries that do not go together, naming the
/// other, or at a TPCTL without a TPSNS.
void check_temperature_program(const config::Config& config);

}  // namespace plcemu::profiles::fb
