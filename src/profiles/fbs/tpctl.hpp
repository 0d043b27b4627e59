#pragma once
// FUN86 TPCTL: PID temperature control of up to 32 points with time-proportioning (PWM) outputs,
// fed by the FBs temperature measurement (FBs manual §21.7).

#include <cstdint>
#include <memory>
#include <optional>

#include "plcemu/engine/engine.hpp"
#include "plcemu/instructions/instructions.hpp"
#include "profiles/fatek/temperature_loop.hpp"
#include "profiles/fbs/temperature_table.hpp"

namespace plcemu::profiles::fbs {

/// Facts of FUN86 that tests and the docs refer to.
namespace tpctl {
/// Full scale of the PID output OR+i.
inline constexpr int kFullScale = 16383;
/// Points one instruction can control.
inline constexpr int kMaxPoints = fatek::kLoopMaxPoints;
/// Words of the instruction's working registers WR.
inline constexpr std::uint32_t kWorkingWords = fatek::kLoopStatusWords;
/// Gains a point whose PR is 0 gets on the first execution.
inline constexpr std::uint16_t kDefaultKc = 110;  ///< Kc
inline constexpr std::uint16_t kDefaultKi = 17;   ///< Ki, 0.01 repeats/min
inline constexpr std::uint16_t kDefaultTd = 50;   ///< Td, 0.01 min
/// Consecutive scans at or above R4008 before the over-temperature warning.
inline constexpr int kOverTemperatureScans = fatek::kOverTemperatureScans;
/// A reading that means "no temperature" (broken sensor, FBs manual §21.3).
inline constexpr std::uint16_t kBrokenReading = temperature::kBroken;
/// The temperature execute code that lets TPCTL run.
inline constexpr std::uint8_t kMeasurementRunning = temperature::kRunning;
/// R4003 value that takes the PVs from the block named by R4004.
inline constexpr std::uint16_t kPvRemap = 0xA55A;
}  // namespace tpctl

/// `TPCTL: {en: M0, hc: 1, md: 0, yn: Y30, sn: 0, zn: 10, sv: R100, os: R110, pr: R120,
/// ir: R130, dr: R140, or: R200, wr: R300, err: M100, alm: M101}`. Throws instructions::BindError
/// naming the operand for an invalid operand or working registers that overlap another TPCTL's.
/// It declares its PWM outputs as the actuators of channels Sn…Sn+Zn−1, and owns WR, OR and Yn.
std::unique_ptr<engine::Instruction> make_tpctl(const instructions::Entry& ic,
                                                const instructions::BindContext& ctx);

}  // namespace plcemu::profiles::fbs
