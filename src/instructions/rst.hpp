#pragma once
// RST: resets a timer, a counter or a device, as the FX family's RST does.

#include <memory>

#include "plcemu/engine/engine.hpp"
#include "plcemu/instructions/instructions.hpp"

namespace plcemu::instructions {

/// `RST: {en: X1, d: C0}`: in every scan while EN is ON, D is reset. A timer or counter (T, C)
/// loses its contact and its value (both words of a 32-bit counter), a Y, M or S relay goes
/// OFF, a register is set to 0.
std::unique_ptr<engine::Instruction> make_rst(const Entry& ic, const BindContext& ctx);

}  // namespace plcemu::instructions
