#pragma once
// FNC92 TPID, the VB's multi-channel temperature PID with time-proportioned outputs and
// per-channel auto-tuning (VB manual FNC92, "Temperature PID Control"; docs/profile-vb.md,
// "FNC92 TPID").

#include <memory>

#include "plcemu/engine/engine.hpp"
#include "plcemu/instructions/instructions.hpp"

namespace plcemu::profiles::vb {

/// `TPID: {en: X0, s1: D7000, s2: D0, s3: D100, s4: D7100, n: 16}`: while EN is ON, channel
/// m = 0…n−1 controls PV S2+m towards SV S1+m. S3 holds the control cycle, the sensitivity and
/// the per-channel bits (direction, auto/manual, AT, outputs, alarms) and the analog outputs
/// S3+10(m+1); S4+6m the channel's Kp, TI, TD, overshoot repression and alarm settings. `n` is
/// a constant or a D register; outside 1–16 the instruction does not execute (error 6705).
std::unique_ptr<engine::Instruction> make_tpid(const instructions::Entry& ic,
                                               const instructions::BindContext& ctx);

}  // namespace plcemu::profiles::vb
