#pragma once
// Operands of FATEK's temperature instructions (FBs FUN86, FB FUN72/FUN73/FUN85/FUN86): their
// register blocks may lie in HR R0–R3839, ROR R5000–R8071 or D, never across the IR/OR/SR words
// between them.

#include <cstdint>

#include "instructions/operands.hpp"
#include "profiles/fatek/temperature_loop.hpp"

namespace plcemu::profiles::fatek {

/// A block of `span` registers in R0–R3839, R5000–R8071 or the PLC's D area; fails at `key`
/// otherwise.
image::Device register_block(instructions::Operands& ops, const char* key, std::uint32_t span);

/// A temperature loop's per-point blocks `sv`, `os`, `pr`, `ir`, `dr` and `or`, `span` words
/// each, into `into`.
void bind_point_blocks(instructions::Operands& ops, std::uint32_t span, LoopBlocks& into);

}  // namespace plcemu::profiles::fatek
