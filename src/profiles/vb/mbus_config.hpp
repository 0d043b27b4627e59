#pragma once
// The VB `mbus:` section: the CP2 port FNC149 MBUS polls its slaves through, over TCP (one
// endpoint, optional per-station routes) or a serial line of its own (VB manual FNC149;
// docs/profile-vb.md, "FNC149 MBUS").

#include <optional>

#include "plcemu/config/config.hpp"
#include "plcemu/config/master.hpp"
#include "plcemu/config/reader.hpp"

namespace plcemu::profiles::vb {

/// Reads the `mbus:` section of `config` (nothing without one) with `r`, each key and route on
/// its own (an error recorded where `r` records errors, else thrown), and checks it against the
/// rest of the config: a program with MBUS needs it, and its serial device may not be the slave
/// port's.
std::optional<config::MasterConfig> read_mbus(const config::Config& config,
                                              const config::Reader& r);

}  // namespace plcemu::profiles::vb
