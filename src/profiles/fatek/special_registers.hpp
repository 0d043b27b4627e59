#pragma once
// The special relays and registers the FATEK families (FBs, FB) share: the same numbers with the
// same meanings (FBs manual §21.3, §21.7 and its special relay and register tables; the FB
// manual's FUN86/FUN73 pages give R4005–R4013 the same meanings).

#include <cstdint>

namespace plcemu::profiles::fatek::special {

/// Special relays.
inline constexpr std::uint32_t kClock10ms = 1920;   ///< M1920 0.01 s square wave
inline constexpr std::uint32_t kClock100ms = 1921;  ///< M1921 0.1 s square wave
inline constexpr std::uint32_t kClock1s = 1922;     ///< M1922 1 s square wave
inline constexpr std::uint32_t kClock60s = 1923;    ///< M1923 60 s square wave
inline constexpr std::uint32_t kFirstScan = 1924;   ///< M1924 first-scan pulse
inline constexpr std::uint32_t kRun = 1926;         ///< M1926 RUN

/// Special registers.
inline constexpr std::uint32_t kPidTiming = 4005;          ///< R4005 solution interval / PWM cycle
inline constexpr std::uint32_t kHeaterOpenPercent = 4006;  ///< R4006
inline constexpr std::uint32_t kHeaterOpenSeconds = 4007;  ///< R4007
inline constexpr std::uint32_t kOverTemperature = 4008;    ///< R4008
inline constexpr std::uint32_t kTempUnit = 4009;           ///< R4009 0 °C, 1 °F
inline constexpr std::uint32_t kSensorInstalled = 4010;    ///< R4010/R4011
inline constexpr std::uint32_t kPidEnable = 4012;          ///< R4012/R4013
inline constexpr std::uint32_t kTempAverage = 4015;        ///< R4015
inline constexpr std::uint32_t kCpuStatus = 4049;          ///< R4049
inline constexpr std::uint32_t kStation = 4055;            ///< R4055
inline constexpr std::uint32_t kPowerUps = 4057;           ///< R4057
inline constexpr std::uint32_t kCalendar = 4128;           ///< R4128–R4134
inline constexpr std::uint32_t kScanTime = 4136;           ///< R4136 current, R4137 max, R4138 min
inline constexpr std::uint32_t kModelCode = 4167;          ///< R4167

}  // namespace plcemu::profiles::fatek::special
