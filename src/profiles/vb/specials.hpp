#pragma once
// The VB special relays and registers the PLC keeps each scan: the FX2N ones moved up by 1000
// (M8000 → M9000, D8010 → D9010), as the VB manual's FNC88/FNC92/FNC149 pages use them
// (docs/profile-vb.md, "Special relays and registers").

#include <cstdint>
#include <memory>

#include "plcemu/engine/specials.hpp"
#include "plcemu/engine/tags.hpp"

namespace plcemu::profiles::vb {

namespace special {

/// Special relays.
inline constexpr std::uint32_t kRun = 9000;             ///< M9000 RUN monitor, always ON
inline constexpr std::uint32_t kAlwaysOff = 9001;       ///< M9001 always OFF
inline constexpr std::uint32_t kFirstScan = 9002;       ///< M9002 initial pulse
inline constexpr std::uint32_t kAfterFirst = 9003;      ///< M9003 OFF in the first scan, then ON
inline constexpr std::uint32_t kClock10ms = 9011;       ///< M9011 10 ms clock
inline constexpr std::uint32_t kClock100ms = 9012;      ///< M9012 100 ms clock
inline constexpr std::uint32_t kClock1s = 9013;         ///< M9013 1 s clock
inline constexpr std::uint32_t kClock1min = 9014;       ///< M9014 1 min clock
inline constexpr std::uint32_t kOperationError = 9067;  ///< M9067 operation error
inline constexpr std::uint32_t kMbusPass = 9199;        ///< M9199 MBUS pass complete, one scan
inline constexpr std::uint32_t kCountDown = 9200;       ///< M9200–M9234 direction of C200–C234
inline constexpr std::uint32_t kCountDownRelays = 35;   ///< M9200–M9234: 35 relays

/// Special registers.
inline constexpr std::uint32_t kScanTime = 9010;  ///< D9010 current, D9011 min, D9012 max
inline constexpr std::uint32_t kCalendar =
    9013;  ///< D9013–D9019 s, min, h, day, month, year, weekday
inline constexpr std::uint32_t kErrorCode = 9067;    ///< D9067 operation error code
inline constexpr std::uint32_t kErrorEntry = 9069;   ///< D9069 program entry that set D9067
inline constexpr std::uint32_t kMbusTimeout = 9129;  ///< D9129 MBUS slave time-out, 10 ms

}  // namespace special

/// M9000–M9003, M9011–M9014, D9010–D9019, and the power-up values of M9067, D9067, D9069,
/// D9129.
std::unique_ptr<engine::Specials> make_specials();

/// What the special relays and registers hold, for the tag export.
engine::Tags special_tags();

}  // namespace plcemu::profiles::vb
