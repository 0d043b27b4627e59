#pragma once
// The FB's FUN86 TPCTL: PID on up to 24 points of the FB-4AJ(K)xx that FUN85 TPSNS measures,
// with PWM outputs (FB manual FUN86; docs/profile-fb.md, "FUN86 TPCTL"). Same number, other
// instruction than the FBs FUN86: the loop is TSTC's.

#include <cstdint>
#include <memory>

#include "plcemu/engine/engine.hpp"
#include "plcemu/instructions/instructions.hpp"

namespace plcemu::profiles::fb {

/// Facts of the FB's FUN86 that tests and the docs refer to.
namespace tpctl {
/// Words of the working registers ("It takes 9 registers").
inline constexpr std::uint32_t kWorkingWords = 9;
/// Sn 0–23, Zn 1–24, Sn + Zn ≤ 24.
inline constexpr int kMaxPoints = 24;
}  // namespace tpctl

/// `TPCTL: {en: M0, hc: 1, yn: Y30, sn: 0, zn: 24, sv: R100, os: R130, pr: R160, ir: R190,
/// dr: R220, or: R300, wr: R260, err: M100, alm: M101}`. Throws instructions::BindError naming
/// the operand. It owns OR…OR+Zn−1, PR/IR/DR…+Zn−1, Yn…Yn+Zn−1, WR…WR+8, ERR and ALM, reads
/// SV/OS…+Zn−1, and drives channels Sn…Sn+Zn−1 (the load checks: docs/profile-fb.md).
std::unique_ptr<engine::Instruction> make_tpctl(const instructions::Entry& ic,
                                                const instructions::BindContext& ctx);

}  // namespace plcemu::profiles::fb
