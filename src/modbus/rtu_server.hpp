#pragma once
// Modbus RTU transport: a serial device read asynchronously on the event loop, framed by the
// t3.5 silence (RtuFramer), answered by the Dispatcher. Nothing here blocks: a slow or noisy
// line never delays TCP clients or the scan.

#include <asio.hpp>
#include <cstdint>
#include <memory>
#include <string>

#include "plcemu/modbus/dispatcher.hpp"
#include "rtu_framer.hpp"

namespace plcemu::modbus {

/// Serial line settings (default 9600 8E1).
struct RtuOptions {
    std::string device;  ///< e.g. /dev/ttyUSB0 or a pty
    int baud = 9600;     ///< bits per second
    char parity = 'E';   ///< 'N', 'E' or 'O'
    int data_bits = 8;   ///< 7 or 8
    int stop_bits = 1;   ///< 1 or 2
};

/// The settings as users write them: "/dev/ttyUSB0 9600 8E1".
std::string describe(const RtuOptions& o);

/// The serial slave. A device that goes away while running (read error, hang-up) is closed and
/// reopened by its path with back-off (0.1 s doubling to 5 s), logged once when lost and once
/// when back.
class RtuServer {
public:
    /// Opens and configures the device (raw, baud, parity, data and stop bits) and starts
    /// reading; throws std::system_error when it cannot.
    RtuServer(asio::io_context& io, Dispatcher& dispatcher, RtuOptions options);
    ~RtuServer();
    RtuServer(const RtuServer&) = delete;
    RtuServer& operator=(const RtuServer&) = delete;

    /// Device and line settings, as logged.
    std::string description() const;
    /// What the framer saw so far.
    const RtuFramerStats& stats() const;
    /// Stops reading (and reopening) and closes the device.
    void stop();

    struct State;

private:
    std::shared_ptr<State> state_;
};

}  // namespace plcemu::modbus
