#pragma once
// FB special registers (FB manual FUN72/FUN73 and FUN85/FUN86; docs/profile-fb.md, "Special
// registers"): the ones every FATEK family has, and the FB temperature registers.

#include <cstdint>

#include "profiles/fatek/special_registers.hpp"

namespace plcemu::profiles::fb::special {

// The FATEK relays and registers (clocks, R4005–R4015, R4049…R4167), by the same names.
using namespace fatek::special;  // NOLINT(google-build-using-namespace)

/// Temperature points: TP0–TP31 (FB-2A…4 modules, Sm = 0…28) or 0–23 (FB-4AJ(K)xx).
inline constexpr std::uint16_t kPoints = 32;
/// R3968+p: raw reading of point p ("R3968 (TP0)…R3999 (TP31)").
inline constexpr std::uint16_t kRawReadings = 3968;
/// R4004: FUN85 TPSNS, ms between two groups of multiplexed points.
inline constexpr std::uint32_t kTpsnsInterval = 4004;
/// R4014: FUN72/FUN73, ms between two multiplexed points of a module.
inline constexpr std::uint32_t kPointInterval = 4014;
/// R4016/R4017: K thermocouple factor, positive / negative temperatures.
inline constexpr std::uint32_t kFactorKPositive = 4016;
inline constexpr std::uint32_t kFactorKNegative = 4017;  ///< R4017
/// R4018/R4019: J thermocouple factor, positive / negative temperatures.
inline constexpr std::uint32_t kFactorJPositive = 4018;
inline constexpr std::uint32_t kFactorJNegative = 4019;  ///< R4019
/// R4020: high byte 0 DIN / 1 JIS; low byte 1 compensation table in R, 2 in D.
inline constexpr std::uint32_t kRtdStandard = 4020;
/// R4021: register number of the line-resistance compensation table (0.1 Ω per point).
inline constexpr std::uint32_t kCompensationTable = 4021;
/// R4022/R4023: Pt100 / Pt1000 linearity factor (reading × F / 1024).
inline constexpr std::uint32_t kFactorPt100 = 4022;
inline constexpr std::uint32_t kFactorPt1000 = 4023;  ///< R4023

/// Power-up values (docs/profile-fb.md, "Special registers").
namespace defaults {
inline constexpr std::uint16_t kTpsnsInterval = 333;  ///< R4004: 6 × 333 ms ≈ 2 s for 24 points
inline constexpr std::uint16_t kPidTiming = 0x0000;   ///< R4005: Ts 2 s, PWM 2 s
inline constexpr std::uint16_t kHeaterOpenPercent = 90;    ///< R4006
inline constexpr std::uint16_t kHeaterOpenSeconds = 600;   ///< R4007
inline constexpr std::uint16_t kOverTemperature = 350;     ///< R4008, whole degrees
inline constexpr std::uint16_t kPointInterval = 500;       ///< R4014: a 4-point round in 2 s
inline constexpr std::uint16_t kFactorKPositive = 248;     ///< R4016
inline constexpr std::uint16_t kFactorKNegative = 286;     ///< R4017
inline constexpr std::uint16_t kFactorJPositive = 240;     ///< R4018
inline constexpr std::uint16_t kFactorJNegative = 280;     ///< R4019
inline constexpr std::uint16_t kRtdStandard = 0x0001;      ///< R4020: DIN, table in R
inline constexpr std::uint16_t kCompensationTable = 8000;  ///< R4021: R8000–R8031
inline constexpr std::uint16_t kFactorRtd = 1024;          ///< R4022, R4023
}  // namespace defaults

}  // namespace plcemu::profiles::fb::special
