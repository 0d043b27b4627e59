#pragma once
// FNC88 PID: a velocity-form PID loop over D registers, with a 25-word parameter block S3, PV
// and MV change alarms, an MV limit and relay auto-tuning (VB manual FNC88; docs/profile-vb.md,
// "FNC88 PID").

#include <cstdint>
#include <memory>

#include "plcemu/engine/engine.hpp"
#include "plcemu/instructions/instructions.hpp"
#include "profiles/vb/operation_error.hpp"

namespace plcemu::profiles::vb {

/// Facts of FNC88 that tests and the docs refer to.
namespace pid {

/// Words the loader reserves for S3 (VB manual FNC88: "S3 occupies 25 consecutive registers").
inline constexpr std::uint32_t kBlockWords = 25;

/// Word offsets in S3.
inline constexpr std::uint32_t kSampling = 0;      ///< Ts, 1–32767 ms
inline constexpr std::uint32_t kControl = 1;       ///< action and alarm control bits
inline constexpr std::uint32_t kFilter = 2;        ///< input filter α, 0–99 %
inline constexpr std::uint32_t kGain = 3;          ///< Kp, 1–32767 %
inline constexpr std::uint32_t kIntegral = 4;      ///< TI, × 100 ms, 0 = no I action
inline constexpr std::uint32_t kDerivGain = 5;     ///< KD, 0–100 %
inline constexpr std::uint32_t kDerivative = 6;    ///< TD, × 10 ms, 0 = no D action
inline constexpr std::uint32_t kTuneHigh = 14;     ///< auto-tuning output at 100 %
inline constexpr std::uint32_t kTuneLow = 15;      ///< auto-tuning output at 0 %
inline constexpr std::uint32_t kPvRiseAlarm = 20;  ///< PV change alarm (+)
inline constexpr std::uint32_t kPvFallAlarm = 21;  ///< PV change alarm (−), used as negative
inline constexpr std::uint32_t kMvUpper = 22;      ///< b2: MV change alarm (+); b5: MV upper limit
inline constexpr std::uint32_t kMvLower = 23;  ///< b2: MV change alarm (−); b5: MV lower limit
inline constexpr std::uint32_t kAlarms = 24;   ///< alarm flags written by the instruction

/// Bits of S3+1.
inline constexpr std::uint16_t kReverse = 1u << 0;    ///< 0 = Forward (cooling), 1 = Reverse
inline constexpr std::uint16_t kPvAlarmOn = 1u << 1;  ///< PV change alarm
inline constexpr std::uint16_t kMvAlarmOn = 1u << 2;  ///< MV change alarm
inline constexpr std::uint16_t kAutoTune = 1u << 4;   ///< run auto-tuning, cleared when done
inline constexpr std::uint16_t kMvLimitOn = 1u << 5;  ///< MV upper/lower limit

/// Bits of S3+24.
inline constexpr std::uint16_t kPvRose = 1u << 0;  ///< PV rose more than S3+20
inline constexpr std::uint16_t kPvFell = 1u << 1;  ///< PV fell more than S3+21
inline constexpr std::uint16_t kMvRose = 1u << 2;  ///< MV rose more than S3+22
inline constexpr std::uint16_t kMvFell = 1u << 3;  ///< MV fell more than S3+23

/// Operation error codes in D9067 (VB manual FNC88, error table); 6750, the auto-tuning fault,
/// is vb::kTuningFault (TPID stores it too).
enum Code : std::uint16_t {
    kBadSampling = 6730,           ///< Ts < 1 (stops)
    kBadFilter = 6732,             ///< α outside 0–99 (stops)
    kBadGain = 6733,               ///< Kp < 1 (stops)
    kBadIntegral = 6734,           ///< TI < 0 (stops)
    kBadDerivGain = 6735,          ///< KD outside 0–100 (stops)
    kBadDerivative = 6736,         ///< TD < 0 (stops)
    kSamplingTooShort = 6740,      ///< Ts ≤ scan interval: samples every scan
    kPvChangeOverflow = 6742,      ///< ΔPV outside 16 bits
    kEvChangeOverflow = 6743,      ///< ΔEV outside 16 bits
    kIntegralOverflow = 6744,      ///< integral term outside 16 bits
    kProportionalOverflow = 6745,  ///< proportional term outside 16 bits ("Kp too large")
    kDerivativeOverflow = 6746,    ///< derivative term outside 16 bits
    kMvOverflow = 6747,            ///< MV outside 16 bits (no limit)
};

}  // namespace pid

/// `PID: {en: X0, s1: D100, s2: D101, s3: D200, d: D102}`: SV, PV, parameter block, MV. All
/// four are D registers, and S3…S3+24 lie in D0–D7999. Throws instructions::BindError at the
/// operand for anything else, and at s3 when the block overlaps one an earlier entry owns
/// (naming that entry). It claims S3…S3+24 as its working registers.
std::unique_ptr<engine::Instruction> make_pid(const instructions::Entry& entry,
                                              const instructions::BindContext& ctx);

}  // namespace plcemu::profiles::vb
