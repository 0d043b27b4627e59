#pragma once
// The descriptor limit against modbus.tcp.max_clients: every client costs one descriptor, and
// running out makes accept() fail (the listener then backs off, see src/listener/tcp_listener.cpp).

#include <string>

namespace plcemu::daemon {

/// Descriptors kept for everything but the clients: listeners, the state file, the event loop,
/// the serial port, a reload's second PLC, the log.
inline constexpr long kFdReserve = 64;
/// Descriptors a reload's second PLC, a config being read and the log may open beside those open
/// now: kept from the clients.
inline constexpr long kFdHeadroom = 16;

/// Descriptors open now, or -1 where /proc is not there.
long open_descriptors() noexcept;

/// Raises the soft RLIMIT_NOFILE up to the hard one when `needed` + kFdReserve need it (logged
/// when it does, saying they are for `what`: "modbus.tcp.max_clients 64"). Nothing is said when
/// even the hard limit is too low: ensure_fd_limit says it once the listeners are open.
void raise_soft_fd_limit(int needed, const std::string& what) noexcept;

/// raise_soft_fd_limit(), then a warning when even the hard limit is too low, saying how many
/// clients the rest leaves (`clients_open`, the clients connected now, are not the daemon's own
/// descriptors). Returns the soft limit in force.
long ensure_fd_limit(int needed, const std::string& what, long clients_open = 0) noexcept;

}  // namespace plcemu::daemon
