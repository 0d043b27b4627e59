#pragma once
// The VB `mbus:` section: the CP2 port FNC149 MBUS polls its slaves through, over TCP (one
// endpoint, optional per-station routes) or a serial line of its own (VB manual FNC149;
// docs/profile-vb.md, "FNC149 MBUS").

#include <optional>

#include "plcemu/config/config.hpp"
#include "plcemu/config/master.hpp"

namespace plcemu::profiles::vb {

/// The `mbus:` section of a config (nothing without one), checked against the rest of the
/// config: a program with MBUS needs it, and its serial device may not be the slave port's.
/// Throws config::ConfigError at the faulty node.
std::optional<config::MasterConfig> mbus_config(const config::Config& config);

}  // namespace plcemu::profiles::vb
