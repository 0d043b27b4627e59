#pragma once
// FNC169 HOUR / DHOUR, the VB hour meter (VB manual FNC169; docs/profile-vb.md, "FNC169 HOUR").

#include <memory>

#include "plcemu/engine/engine.hpp"
#include "plcemu/instructions/instructions.hpp"

namespace plcemu::profiles::vb {

/// `HOUR: {en: X0, s: 1000, d1: D7000, d2: Y0}`: while EN is ON, the time since the previous
/// scan is added to the hours in D1 and the seconds below an hour in D1+1; D2 (Y, M or S) is ON
/// while the hours are at least S. The count stops at 32767 h 3599 s.
std::unique_ptr<engine::Instruction> make_hour(const instructions::Entry& ic,
                                               const instructions::BindContext& ctx);

/// `DHOUR`: the same with 32-bit hours in (D1+1, D1), low word first, the seconds in D1+2 and
/// a 32-bit S; the count stops at 2147483647 h 3599 s.
std::unique_ptr<engine::Instruction> make_dhour(const instructions::Entry& ic,
                                                const instructions::BindContext& ctx);

}  // namespace plcemu::profiles::vb
