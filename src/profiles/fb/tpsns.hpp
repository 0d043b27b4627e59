#pragma once
// FUN85 TPSNS: the measurement of the FB-4AJ(K)xx multiplexed thermocouple module, 12 to 24
// points read four at a time, whose readings the FB's FUN86 TPCTL controls on (FB manual
// FUN85/FUN86; docs/profile-fb.md, "FUN85 TPSNS").

#include <cstdint>
#include <memory>

#include "plcemu/engine/engine.hpp"
#include "plcemu/instructions/instructions.hpp"

namespace plcemu::profiles::fb {

/// Facts of FUN85 that tests and the docs refer to.
namespace tpsns {
/// Words of the working registers: broken bits (points 0–15, 16–23), read-once bits (the same).
inline constexpr std::uint32_t kWorkingWords = 4;
/// Points when `temperature.modules` names no FB-4AJ(K)xx: the largest module's.
inline constexpr int kDefaultPoints = 24;
/// The module's analog inputs, sampled together: points 4g…4g+3 are group g.
inline constexpr int kInputs = 4;
}  // namespace tpsns

/// `TPSNS: {en: M1, tp: 0, pl: 0, tr: R0, wr: R250, err: M120, alm: M121}`. Throws
/// instructions::BindError naming the operand. It owns TR…TR+N−1, WR…WR+3, R3968…R3968+N−1 (N
/// the module's points), ERR and ALM; none may overlap another's (docs/profile-fb.md).
std::unique_ptr<engine::Instruction> make_tpsns(const instructions::Entry& ic,
                                                const instructions::BindContext& ctx);

}  // namespace plcemu::profiles::fb
