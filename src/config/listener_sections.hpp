#pragma once
// Reading the sections that name listeners: modbus.tcp and the FATEK protocol's fatek.tcp,
// fatek.udp and fatek.serial (docs/configuration.md).

#include <string>

#include "plcemu/config/config.hpp"
#include "plcemu/config/reader.hpp"

namespace plcemu::config {

/// Reads a TCP or UDP listener's keys into `tcp`; `what` ("modbus.tcp", "fatek.udp") names the
/// section, and says which keys it takes: a UDP listener has no connections to limit, a FATEK
/// one has its own `read_only` and no unit-ID policy.
void read_tcp(const Reader& r, const Node& n, TcpConfig& tcp, const std::string& what);

/// Reads a serial line's settings, with `read_only` among its keys when `with_read_only` and
/// `echo` when it is a PLC's (`slave`) line.
void read_line(const Reader& r,
               const Node& n,
               RtuConfig& rtu,
               const std::string& what,
               bool with_read_only,
               bool slave);

/// Reads `http:` (the console and REST API; docs/console.md); `on_anyway` (the command line's
/// --http-port) keeps a console the section turns off.
void read_http(const Reader& r,
               const Node& n,
               std::optional<TcpConfig>& http,
               bool on_anyway = false);
/// Reads `fatek:`.
void read_fatek(const Reader& r, const Node& n, FatekConfig& fatek);

}  // namespace plcemu::config
