#pragma once
// How WinProladder writes a FATEK program as an instruction list (its mnemonic view), and the
// timers and counters those programs use (docs/program-language.md, "fbs and fb").

#include <vector>

#include "plcemu/instructions/listing.hpp"
#include "instructions/tmr.hpp"

namespace plcemu::profiles::fatek {

/// The mnemonic view's statements, with the function instructions `functions` (those of the
/// family: each profile has its own).
instructions::Dialect listing_dialect(std::vector<instructions::FunctionSpelling> functions);

/// The time bases of T0–T255 as a FATEK PLC leaves its factory: T0–T49 0.01 s, T50–T199 0.1 s,
/// T200–T255 1 s, none retentive.
std::vector<instructions::TimerGroup> timer_groups();

}  // namespace plcemu::profiles::fatek
