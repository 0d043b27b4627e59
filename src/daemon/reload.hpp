#pragma once
// What a reload changes: the differences between two configs, as log lines.

#include <string>
#include <vector>

#include "plcemu/config/config.hpp"

namespace plcemu::daemon {

/// One line per setting that differs ("station: 1 -> 5"), in config order. Sections compared as a
/// whole say only that they changed ("program: changed (3 instructions)").
/// State files are placed in `state_directory` ($STATE_DIRECTORY; "": beside the config), as the
/// daemon places them.
std::vector<std::string> config_changes(const config::Config& before,
                                        const config::Config& after,
                                        const std::string& state_directory = "");

}  // namespace plcemu::daemon
