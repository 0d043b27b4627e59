#pragma once
// The `faults:` section (docs/communication-faults.md): the communication faults a PLC has from
// start-up, with the names the REST API and the simulator unit use.

#include "plcemu/config/comm_faults.hpp"
#include "plcemu/config/node.hpp"
#include "plcemu/config/reader.hpp"

namespace plcemu::config {

/// Reads `faults:` into `s`; throws ConfigError at the key at fault.
void read_comm_faults(const Reader& r, const Node& f, CommFaultSettings& s);

}  // namespace plcemu::config
