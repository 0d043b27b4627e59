#pragma once
// The loader's second half: a config tree (config/node.hpp), however it was read, to a checked
// Config. parse_config() is the YAML text front of it; a fuzz harness feeds it trees directly,
// so that every input reaches the sections, the profile's checks and the program instead of
// spending its time in the YAML library (docs/development.md, "Fuzzing").

#include <string>

#include "plcemu/config/config.hpp"
#include "plcemu/config/node.hpp"

namespace plcemu::config {

/// Reads and validates a config tree whose root is `root`; `name` becomes Config::path, and
/// `overrides` (the command line's) are applied before the checks. Throws ConfigError at the
/// position of the node at fault.
Config read_config(const Node& root, const std::string& name, const Overrides& overrides = {});

}  // namespace plcemu::config
