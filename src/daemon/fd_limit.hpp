#pragma once
// The descriptor limit against modbus.tcp.max_clients: every client costs one descriptor, and
// running out makes accept() fail (the listener then backs off, see src/listener/tcp_listener.cpp).

namespace plcemu::daemon {

/// Descriptors kept for everything but the clients: listeners, the state file, the event loop,
/// the serial port, a reload's second PLC, the log.
inline constexpr long kFdReserve = 64;

/// Raises the soft RLIMIT_NOFILE up to the hard one when `max_clients` + kFdReserve need it, and
/// logs a warning when even the hard limit is too low. Returns the soft limit in force.
long ensure_fd_limit(int max_clients) noexcept;

}  // namespace plcemu::daemon
