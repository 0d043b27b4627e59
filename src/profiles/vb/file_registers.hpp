#pragma once
// The VB `file_registers:` section: a range of D registers that holds program data (VB manual
// FNC149: "File Registers are read only registers and their contents are assumed as a part of
// program"; docs/profile-vb.md, "File registers").

#include <optional>

#include "plcemu/config/config.hpp"
#include "plcemu/image/area.hpp"

namespace plcemu::profiles::vb {

/// `file_registers: D1000-D1099`, or nothing. Throws config::ConfigError at the faulty node.
std::optional<image::Range> file_registers(const config::Config& config);

}  // namespace plcemu::profiles::vb
