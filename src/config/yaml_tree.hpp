#pragma once
// The loader's first half: YAML text to a config tree (plcemu/config/node.hpp).

#include <string>

#include "plcemu/config/node.hpp"

namespace plcemu::config {

/// The first YAML document of `text` as a tree whose positions name `name`; an empty text is a
/// null node at 1:1. Throws ConfigError at the position of a YAML syntax error, or of a node
/// past the nesting and size limits (aliases may stand for an exponential tree).
Node parse_yaml_tree(const std::string& text, const std::string& name);

}  // namespace plcemu::config
