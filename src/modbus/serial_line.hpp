#pragma once
// A serial line as the RTU slave and the RTU master open it: the device path and the line
// settings, a non-blocking raw descriptor set up from them.

#include <string>

#include "plcemu/modbus/line_settings.hpp"

namespace plcemu::modbus {

/// The settings as users write them: "/dev/ttyUSB0 9600 8E1".
std::string describe(const RtuOptions& o);

/// Opens the device non-blocking and sets the line: raw bytes, no flow control, no modem lines,
/// the baud rate, parity and data and stop bits (a setting the device does not take, as a pty
/// takes none, is logged). Whatever waited on the line is flushed. Returns the descriptor;
/// throws std::system_error when the device cannot be opened or configured.
int open_serial_line(const RtuOptions& o, const std::string& name = "rtu");

}  // namespace plcemu::modbus
