#pragma once
// FBs special relays and registers (FBs manual §21.3, §21.7; docs/profile-fbs.md, "Scan cycle and
// special registers"): the ones every FATEK family has, and the FBs' own.

#include <cstdint>

#include "profiles/fatek/special_registers.hpp"

namespace plcemu::profiles::fbs::special {

// The FATEK relays and registers (clocks, R4005–R4015, R4049…R4167), by the same names.
using namespace fatek::special;  // NOLINT(google-build-using-namespace)

/// R4003/R4004 of the FBs temperature measurement (FBs manual §21.3).
inline constexpr std::uint32_t kTempMeasureRemap = 4003;  ///< R4003 = A55Ah: PV from R4004
inline constexpr std::uint32_t kTempPvSource = 4004;      ///< R4004 encoded PV start

}  // namespace plcemu::profiles::fbs::special
