#pragma once
// The format of the daemon's log lines. Whatever a line quotes — a config key, a file name, a
// device path, a peer's reply — is escaped as one place, here: a control or bidi character in a
// config cannot break, forge or reorder a terminal line (docs/operations.md, "Logging").

#include <spdlog/formatter.h>

#include <memory>

namespace plcemu::daemon {

/// "2024-05-01 12:00:00.123 info  message", the message escaped as image::excerpt escapes (never
/// cut).
std::unique_ptr<spdlog::formatter> log_formatter();

}  // namespace plcemu::daemon
