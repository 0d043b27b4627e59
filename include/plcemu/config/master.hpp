#pragma once
// A Modbus master port as plain values: where a program's master instruction (the VB's FNC149
// MBUS through its CP2 port) sends its requests. A profile reads it from its own config section
// (Profile::master); the daemon opens it on its event loop.

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "plcemu/config/config.hpp"

namespace plcemu::config {

/// A TCP endpoint: an IP address (v4 or v6) and a port.
struct TcpEndpoint {
    std::string host;        ///< IP address as written
    std::uint16_t port = 0;  ///< port

    bool operator==(const TcpEndpoint&) const = default;
};

/// One station reached through an endpoint of its own.
struct MasterRoute {
    std::uint8_t station = 0;  ///< 1–247
    TcpEndpoint endpoint;      ///< where its requests go
};

/// The wire a master port uses.
enum class MasterTransport : std::uint8_t { Tcp, Rtu };

/// A master port.
struct MasterConfig {
    MasterTransport transport = MasterTransport::Tcp;  ///< TCP or a serial line
    TcpEndpoint tcp;                                   ///< every station not routed (TCP)
    std::vector<MasterRoute> routes;                   ///< per-station endpoints (TCP)
    std::optional<RtuConfig> rtu;                      ///< the serial line (RTU)
};

}  // namespace plcemu::config
