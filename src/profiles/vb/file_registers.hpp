#pragma once
// The VB `file_registers:` section: a range of D registers that holds program data (VB manual
// FNC149: "File Registers are read only registers and their contents are assumed as a part of
// program"; docs/profile-vb.md, "File registers").

#include "plcemu/config/reader.hpp"
#include "plcemu/image/area.hpp"

namespace plcemu::profiles::vb {

/// Reads `file_registers: D1000-D1099` with `r`. Throws config::ConfigError at the faulty node.
image::Range read_file_registers(const config::Reader& r, const config::Node& section);

}  // namespace plcemu::profiles::vb
