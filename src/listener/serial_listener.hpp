#pragma once
// A serial line seat: a device read asynchronously on the event loop, its bytes handed with
// their arrival time to the protocol it was given (plcemu/listener/protocol.hpp), which frames
// and answers them. Nothing here blocks: a slow or noisy line never delays TCP clients or the
// scan.

#include <asio.hpp>
#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <string_view>

#include "plcemu/listener/protocol.hpp"

namespace plcemu::listener {

/// The serial line. A device that goes away while running (read error, hang-up) is closed and
/// reopened by its path with back-off (0.1 s doubling to 5 s), logged once when lost and once
/// when back.
class SerialListener {
public:
    /// Opens and configures the device (raw, baud, parity, data and stop bits) and starts
    /// reading; throws std::system_error when it cannot, unless `wait_for_device`: then it
    /// tries again with back-off as for a device lost (absent() says why). `protocol` must
    /// outlive it; `name` starts its log lines ("rtu"); `protocol_name` is the protocol's, as
    /// the line's master is listed among the clients ("modbus-rtu").
    SerialListener(asio::io_context& io,
                   SerialProtocol& protocol,
                   LineSettings line,
                   std::string name,
                   std::string_view protocol_name,
                   bool wait_for_device = false);
    ~SerialListener();
    SerialListener(const SerialListener&) = delete;
    SerialListener& operator=(const SerialListener&) = delete;

    /// Device and line settings, as logged.
    std::string description() const;
    /// Why the device could not be opened when this was made with `wait_for_device` ("cannot
    /// open /dev/ttyUSB1: No such file or directory"); empty when it was.
    const std::string& absent() const noexcept { return absent_; }
    /// Stops reading (and reopening) and closes the device.
    void stop();
    /// False while the device is gone (lost, or absent since it was made) and is being tried
    /// again; true once it is open.
    bool has_device() const noexcept;
    /// Calls `f` each time has_device() changes (never after stop()).
    void on_device_change(std::function<void()> f);

    struct State;

private:
    std::shared_ptr<State> state_;
    std::string absent_;
};

}  // namespace plcemu::listener
