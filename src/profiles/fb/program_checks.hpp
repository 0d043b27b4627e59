#pragma once
// Rules on the FB temperature instructions a program holds together (FB manual FUN73/FUN85/
// FUN86; docs/profile-fb.md, "FUN85 TPSNS"): the FB-4AJ(K)xx is used alone, so a program with a
// TPSNS has no TP4 or TSTC and one TPSNS at most; a TPCTL needs the TPSNS.

#include <string>
#include <vector>

#include "plcemu/config/config.hpp"
#include "plcemu/profiles/profile.hpp"

namespace plcemu::profiles::fb {

/// Throws config::ConfigError at the later of two instructions of `program`
/// (profiles::program_instructions) that do not go together, naming the other, or at a TPCTL
/// without a TPSNS.
void check_temperature_program(const std::vector<ProgramInstruction>& program);

}  // namespace plcemu::profiles::fb
