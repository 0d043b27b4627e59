#pragma once
// FUN72 TP4: multiplexed temperature measurement of one FB-2AJ(K)4 / FB-2AH(T)4 module (FB manual
// FUN72/FUN73; docs/profile-fb.md, "FUN72 TP4").

#include <memory>

#include "plcemu/engine/engine.hpp"
#include "plcemu/instructions/instructions.hpp"

namespace plcemu::profiles::fb {

/// `TP4: {en: M3, tp: 0, pl: 0, sm: 0, ym: Y16, ar: R3842, tr: R0, wr: R220, err: M110,
/// alm: M111}`. Throws instructions::BindError naming the operand. It owns Ym…Ym+7, AR, TR…TR+3,
/// WR…WR+7 and the raw registers R3968+Sm…+3.
std::unique_ptr<engine::Instruction> make_tp4(const instructions::Entry& ic,
                                              const instructions::BindContext& ctx);

}  // namespace plcemu::profiles::fb
