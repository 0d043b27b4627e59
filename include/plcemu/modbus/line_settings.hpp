#pragma once
// A serial line's settings, as the serial listeners and the RTU master open a line.

#include <string>

namespace plcemu::modbus {

/// Serial line settings (default 9600 8E1).
struct LineSettings {
    std::string device;  ///< e.g. /dev/ttyUSB0 or a pty
    int baud = 9600;     ///< bits per second
    char parity = 'E';   ///< 'N', 'E' or 'O'
    int data_bits = 8;   ///< 7 or 8
    int stop_bits = 1;   ///< 1 or 2
    bool echo = false;   ///< the line hands back what is sent (a slave drops its answers' echo)
};

/// The settings of the Modbus RTU slave and master.
using RtuOptions = LineSettings;

}  // namespace plcemu::modbus
