#pragma once
// Reading the config file: a regular file of bounded size, opened without blocking.

#include <cstddef>
#include <string>

namespace plcemu::config {

/// The largest config file read (docs/configuration.md, "The config file").
inline constexpr std::size_t kMaxConfigBytes = std::size_t{16} << 20;

/// The text of the config file at `path` (a symbolic link is followed). Throws ConfigError naming
/// the path when it cannot be opened, is not a regular file (a directory, FIFO, device or
/// socket), or holds more than kMaxConfigBytes, also when it grows past them while read.
/// `what` names the file in the messages (a program file the config refers to).
std::string read_config_file(const std::string& path, const std::string& what = "the config file");

}  // namespace plcemu::config
