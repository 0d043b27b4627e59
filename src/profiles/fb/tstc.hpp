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
/// Full scale of the PID output OR+i ("值为 0~4095").
inline constexpr int kFullScale = 4095;
/// Kc, Ti and Td above this count as it.
inline constexpr int kGainCeiling = 999;
/// Default Ti (reset time 6 min) and Td (1 min).
inline constexpr std::uint16_t kDefaultTi = 17;
inline constexpr std::uint16_t kDefaultTd = 100;
/// The default Kc of a sensor code and range: thermocouples 60/30/120/60 for Pl 0–3, RTDs (bipolar
/// modules) 120 on a 10 V span and 60 on a 5 V one.
std::uint16_t default_kc(int sensor, int pl);
/// The converter's full scale in the reading's unit (°C/°F, or 0.1 °C/°F for RTDs): the PID's
/// error is scaled by 4095 / full scale.
double full_scale(int sensor, int pl, bool fahrenheit, bool jis);
}  // namespace tstc

/// `TSTC: {en: M0, hc: 1, tp: 0, pl: 0, sm: 0, ym: Y16, ar: R3842, tr: R0, yh: Y48, sh: 0, zh: 4,
/// sv: R100, os: R120, pr: R140, ir: R160, dr: R180, or: R300, wr: R200, err: M100, ao0: M101,
/// ao1: M102}`. Throws instructions::BindError naming the operand. It owns what TP4 owns (with
/// WR 17 words), OR…OR+Zh−1 and Yh…Yh+Zh−1, and drives channels Sh…Sh+Zh−1.
std::unique_ptr<engine::Instruction> make_tstc(const instructions::Entry& ic,
                                               const instructions::BindContext& ctx);

}  // namespace plcemu::profiles::fb
