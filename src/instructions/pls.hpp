#pragma once
// PLS and PLF: a one-scan pulse on the rising or falling edge of its input, as the FX family's.

#include <memory>

#include "plcemu/engine/engine.hpp"
#include "plcemu/instructions/instructions.hpp"

namespace plcemu::instructions {

/// `PLS: {en: X0, d: M0}`: D (Y, M or S) is ON during the scan in which EN turns ON and OFF in
/// every other scan.
std::unique_ptr<engine::Instruction> make_pls(const Entry& ic, const BindContext& ctx);

/// `PLF`: the same on the falling edge: D is ON during the scan in which EN turns OFF.
std::unique_ptr<engine::Instruction> make_plf(const Entry& ic, const BindContext& ctx);

}  // namespace plcemu::instructions
