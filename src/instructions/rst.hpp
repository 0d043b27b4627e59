#pragma once
// RST and ZRST: reset a timer, a counter or a device, or a zone of them, as the FX family's RST
// and FNC40 ZRST do.

#include <memory>

#include "plcemu/engine/engine.hpp"
#include "plcemu/instructions/instructions.hpp"

namespace plcemu::instructions {

/// `RST: {en: X1, d: C0}`: in every scan while EN is ON, D is reset. A timer or counter (T, C)
/// loses its contact and its value (both words of a 32-bit counter), a Y, M or S relay goes
/// OFF, a register is set to 0.
std::unique_ptr<engine::Instruction> make_rst(const Entry& ic, const BindContext& ctx);

/// `ZRST: {en: X1, d1: M0, d2: M99, p: false}` (FNC40): while EN is ON (p: true, ZRSTP: as it
/// turns ON) every device from D1 to D2 is reset as RST resets one; D1 and D2 are of one area,
/// D1 not above D2.
std::unique_ptr<engine::Instruction> make_zrst(const Entry& ic, const BindContext& ctx);

}  // namespace plcemu::instructions
