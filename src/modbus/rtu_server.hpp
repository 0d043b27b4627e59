#pragma once
// Modbus RTU transport: a serial device read asynchronously on the event loop, framed by the
// t3.5 silence (RtuFramer), answered by the Dispatcher. Nothing here blocks: a slow or noisy
// line never delays TCP clients or the scan.

#include <asio.hpp>
#include <cstdint>
#include <memory>
#include <string>

#include "plcemu/modbus/responder.hpp"
#include "rtu_framer.hpp"
#include "serial_line.hpp"

namespace plcemu::modbus {

/// The serial slave. A device that goes away while running (read error, hang-up) is closed and
/// reopened by its path with back-off (0.1 s doubling to 5 s), logged once when lost and once
/// when back.
class RtuServer {
public:
    /// Opens and configures the device (raw, baud, parity, data and stop bits) and starts
    /// reading; throws std::system_error when it cannot.
    RtuServer(asio::io_context& io, Responder& dispatcher, RtuOptions options);
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
