#pragma once
// `plcemud --print-map`: the address map as a table or CSV.

#include <ostream>

#include "plcemu/config/config.hpp"

namespace plcemu::daemon {

/// Writes the map of the config's profile, one row per range, plus the simulator unit.
void print_map(std::ostream& out, const config::Config& config, bool csv);

}  // namespace plcemu::daemon
