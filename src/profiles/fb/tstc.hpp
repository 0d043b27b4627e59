#pragma once
// FUN73 TSTC: the measurement of one FB-2AJ(K)4 / FB-2AH(T)4 module (as TP4) and PID control of
// up to 32 points with PWM outputs (FB manual FUN73; docs/profile-fb.md, "FUN73 TSTC").

#include <cstdint>
#include <memory>

#include "plcemu/engine/engine.hpp"
#include "plcemu/instructions/instructions.hpp"

namespace plcemu::profiles::fb {

/// Facts of FUN73 that tests and the docs refer to.
namespace tstc {
/// Words of the working registers WR: the measurement's 8, then the loop's 9.
inline constexpr std::uint32_t kWorkingWords = 17;
/// WR+8: where the loop's words (in-zone, warnings, timing, causes) start.
inline constexpr std::uint32_t kLoopWords = 8;
}  // namespace tstc

/// `TSTC: {en: M0, hc: 1, tp: 0, pl: 0, sm: 0, ym: Y16, ar: R3842, tr: R0, yh: Y48, sh: 0, zh: 4,
/// sv: R100, os: R120, pr: R140, ir: R160, dr: R180, or: R300, wr: R200, err: M100, ao0: M101,
/// ao1: M102}`. Throws instructions::BindError naming the operand. It owns what TP4 owns (with
/// WR 17 words), OR…OR+Zh−1 and Yh…Yh+Zh−1, and drives channels Sh…Sh+Zh−1.
std::unique_ptr<engine::Instruction> make_tstc(const instructions::Entry& ic,
                                               const instructions::BindContext& ctx);

}  // namespace plcemu::profiles::fb
