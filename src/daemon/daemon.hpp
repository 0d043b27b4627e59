#pragma once
// The running daemon: one event loop with the listeners, the scan timer and the signals.

#include <optional>
#include <string>
#include <vector>

#include "plcemu/config/config.hpp"
#include "plcemu/engine/engine.hpp"

namespace plcemu::daemon {

/// Builds the PLC of `config` on an image of its own, as a check of everything the config can
/// get wrong that the loader cannot (program operands, the allow list), and returns its program,
/// bound and checked. An error names the `plcs:` entry. Throws config::ConfigError.
engine::Program probe(const config::Config& config);

/// probe() for every PLC of a file, in order: the errors of each are reported together, as the
/// loader reports a file's (config::Errors). Throws config::ConfigError.
/// `skip`: the PLCs not to build (a reload's unchanged ones), whose programs are left empty;
/// none when empty.
std::vector<engine::Program> probe_all(const std::vector<config::Config>& configs,
                                       const std::vector<bool>& skip = {});

/// Runs until SIGINT or SIGTERM. Throws config::ConfigError for a bad config and
/// std::system_error when a listener cannot be opened. Returns the exit status.
/// `overrides`: the command line's ports, which config::load_plcs applies at each (re)load.
int run_daemon(const std::string& config_path, const config::Overrides& overrides);

}  // namespace plcemu::daemon
