#pragma once
// What a reload changes: the differences between two configs, as log lines.

#include <string>
#include <vector>

#include "plcemu/config/config.hpp"

namespace plcemu::daemon {

/// One line per setting that differs ("station: 1 -> 5"), in config order. Sections compared as a
/// whole say only that they changed ("program: changed (3 instructions)").
std::vector<std::string> config_changes(const config::Config& before, const config::Config& after);

}  // namespace plcemu::daemon
