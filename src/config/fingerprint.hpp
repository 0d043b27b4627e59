#pragma once
// What a PLC's config was read from, summed: a reload compares the sums to find the PLCs whose
// config did not change.

#include "plcemu/config/config.hpp"
#include "plcemu/config/node.hpp"

namespace plcemu::config {

/// The sum of `root` (the PLC's file, or its entry of `plcs:`) as written, wherever each node
/// stands and without `log:` (the process's, not the PLC's), of the program file's lines, of
/// `shared_http` (the `http:` beside `plcs:` when the entry has none of its own; null when there
/// is none), and of the config's path and position in `plcs:`.
Fingerprint fingerprint(const Config& config, const Node& root, const Node* shared_http);

}  // namespace plcemu::config
