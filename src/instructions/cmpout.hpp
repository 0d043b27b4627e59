#pragma once
// CMPOUT: a compare contact driving an output (the FX family's LD=, LD<>, LD<, LD<=, LD>,
// LD>= followed by OUT).

#include <memory>

#include "plcemu/engine/engine.hpp"
#include "plcemu/instructions/instructions.hpp"

namespace plcemu::instructions {

/// `CMPOUT: {op: '<', s1: TN200, s2: D102, out: Y0}`: in every scan OUT (Y, M or S) = S1 op S2,
/// both read as signed 16-bit words; op is one of = <> < <= > >=.
std::unique_ptr<engine::Instruction> make_cmpout(const Entry& ic, const BindContext& ctx);

}  // namespace plcemu::instructions
