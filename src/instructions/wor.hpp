#pragma once
// WOR: word OR (FX FNC27).

#include <memory>

#include "plcemu/engine/engine.hpp"
#include "plcemu/instructions/instructions.hpp"

namespace plcemu::instructions {

/// `WOR: {en: M0, s1: D0, s2: H00FF, d: D1}`: while EN is ON, D = S1 OR S2 (bit by bit) each
/// scan.
std::unique_ptr<engine::Instruction> make_wor(const Entry& ic, const BindContext& ctx);

}  // namespace plcemu::instructions
