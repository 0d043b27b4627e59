#pragma once
// CMP: compares two words into three relays, as the FX family's FNC10 CMP.

#include <memory>

#include "plcemu/engine/engine.hpp"
#include "plcemu/instructions/instructions.hpp"

namespace plcemu::instructions {

/// `CMP: {en: X0, s1: D0, s2: K100, d: M0, p: false}`: while EN is ON (p: true, CMPP: as it
/// turns ON), D is ON when S1 > S2, D+1 when S1 = S2, D+2 when S1 < S2 (signed); with EN OFF
/// the three keep their state. D is a Y, M or S relay with two more after it.
std::unique_ptr<engine::Instruction> make_cmp(const Entry& ic, const BindContext& ctx);

}  // namespace plcemu::instructions
