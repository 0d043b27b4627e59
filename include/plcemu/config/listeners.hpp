#pragma once
// The listeners a config asks for, whatever section names them: each says the protocol it
// carries (docs/architecture.md, "How to add a protocol"). The loader checks them against each
// other (one port, one protocol) and the daemon opens them from this one list.

#include <string>
#include <string_view>
#include <vector>

#include "plcemu/config/config.hpp"

namespace plcemu::config {

/// What carries a listener's bytes.
enum class Carrier : std::uint8_t { Tcp, Udp, Serial };

/// One listener of a config.
struct ListenerConfig {
    std::string_view protocol;       ///< "modbus-tcp", "modbus-rtu", "fatek"
    Carrier carrier = Carrier::Tcp;  ///< what carries it
    std::string_view section;        ///< where the config names it: "modbus.tcp", "fatek.serial"
    const TcpConfig* net =
        nullptr;  ///< Tcp and Udp: address, port, access (points into the config)
    const RtuConfig* line = nullptr;  ///< Serial: the line's settings (points into the config)
};

/// The listeners `config` turns on, in a fixed order (modbus.tcp, modbus.rtu, fatek.tcp,
/// fatek.udp, fatek.serial). A TCP listener on port 0 counts too (the kernel picks its port).
std::vector<ListenerConfig> listeners_of(const Config& config);

/// What a listener is as the kernel sees it: "tcp ADDR:PORT", "udp ADDR:PORT" (the address as
/// tcp_listener_key writes it) or "serial PATH" (serial_line_key). PLCs whose listeners have one
/// key share that listener.
std::string listener_key(const ListenerConfig& listener);

}  // namespace plcemu::config
