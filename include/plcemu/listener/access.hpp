#pragma once
// The check every protocol makes before a master's write (docs/profile-fbs.md, "FATEK protocol",
// errors; docs/console.md): devices no master may write refuse it, except inputs (X) that are
// disabled (FATEK command 42), which hold what is written to them as on the PLC.

#include <optional>
#include <vector>

#include "plcemu/engine/holds.hpp"
#include "plcemu/image/area.hpp"

namespace plcemu::listener {

/// The protected range that refuses a write of `devices`, or nothing when it may be written.
std::optional<image::Range> write_refused_by(const std::vector<image::Range>* protected_ranges,
                                             const engine::Holds& holds,
                                             const image::Range& devices) noexcept;

}  // namespace plcemu::listener
