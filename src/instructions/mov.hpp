#pragma once
// MOV: word move, so the manuals' example programs can be written down.

#include <memory>

#include "plcemu/engine/engine.hpp"
#include "plcemu/instructions/instructions.hpp"

namespace plcemu::instructions {

/// `MOV: {en: M1926, s: WM800, d: R4012}`: while EN is ON, D = S each scan. With `p: true`
/// (MOVP) only in the scan where EN turns ON.
std::unique_ptr<engine::Instruction> make_mov(const Entry& ic, const BindContext& ctx);

}  // namespace plcemu::instructions
