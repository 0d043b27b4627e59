#pragma once
// What a listener is, as the kernel sees it, whatever way the config writes it: PLCs with one key
// share that listener (docs/configuration.md, "Sharing a listener"). The loader and the daemon's
// listeners compare the same keys, so what --check-config accepts is what the daemon opens.
// A state file has a key of the same kind: the file the kernel would open, however spelled.

#include <string>

#include "plcemu/config/config.hpp"

namespace plcemu::config {

/// "ADDR:PORT" with the bind address parsed (inet_pton, as the listener's address parser does)
/// and written back in its one canonical form: "0:0:0:0:0:0:0:1" and "::1" are one address.
/// An address that does not parse is kept as written.
std::string tcp_listener_key(const TcpConfig& tcp);

/// True when `bind` is the wildcard address of IPv4 or IPv6 (every address), however written.
bool any_address(const std::string& bind);

/// A serial device's path with symlinks resolved when it exists, else made absolute and
/// lexically normal ("/tmp//x" and "/tmp/./x" are "/tmp/x").
std::string serial_line_key(const std::string& device);

/// The state file of a config: persistence.file, or default_state_file(); a relative name lies
/// in $STATE_DIRECTORY (set by systemd's StateDirectory=) when set, else beside the config.
/// `state_directory` is the value of STATE_DIRECTORY ("" = unset; the first of a list counts).
std::string state_file_path(const Config& config, const std::string& state_directory);

/// A state file's path as the kernel reaches it: absolute, every symlink resolved, a dangling one
/// as the last component too (its target is where the file would be), the rest lexically normal.
/// Entries of `plcs:` whose keys are equal would open one file (`x.state`, `./x.state`, a link to
/// it, a path through a linked directory).
std::string state_file_key(const std::string& path);

}  // namespace plcemu::config
