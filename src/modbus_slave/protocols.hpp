#pragma once
// The Modbus slave protocols as listeners name them.

#include "plcemu/listener/protocol.hpp"
#include "rtu.hpp"
#include "tcp.hpp"

namespace plcemu::modbus_slave {

/// Modbus TCP, on TCP listeners (`modbus.tcp`).
inline constexpr listener::ProtocolKind kModbusTcp{"modbus-tcp", &make_tcp, nullptr};
/// Modbus RTU, on serial lines (`modbus.rtu`).
inline constexpr listener::ProtocolKind kModbusRtu{"modbus-rtu", nullptr, nullptr, &make_rtu};

}  // namespace plcemu::modbus_slave
