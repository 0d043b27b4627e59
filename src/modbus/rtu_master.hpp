#pragma once
// Modbus RTU master on the event loop: a serial line of its own (the VB's CP2), requests framed
// as address + PDU + CRC after t3.5 of silence, the reply framed by the same t3.5/t1.5/CRC code
// as the slave side (RtuFramer) and judged by rtu_reply. One transaction at a time; a broadcast
// (station 0) gets no reply. A line that fails (read error, hang-up: an unplugged adapter, a
// socat that went away) is closed; the transaction on it times out and each later one tries
// to open the device again by its path, so a line that stays gone costs one open() per
// transaction and a line that comes back is used again.

#include <asio.hpp>
#include <cstdint>

#include "master_transport.hpp"
#include "serial_line.hpp"

namespace plcemu::modbus {

struct RtuMasterState;

/// The RTU master.
class RtuMaster final : public SharedStateTransport<RtuMasterState> {
public:
    /// How a device that cannot be opened at construction is taken.
    enum class Open : std::uint8_t {
        Now,     ///< throw std::system_error (a start: the config names a device that is not there)
        Lazily,  ///< log it and try again at every transfer, as for a device that went away
    };
    /// Opens and configures the device.
    RtuMaster(asio::io_context& io, RtuOptions options, Open open = Open::Now);
    ~RtuMaster() override;
    RtuMaster(const RtuMaster&) = delete;
    RtuMaster& operator=(const RtuMaster&) = delete;
};

}  // namespace plcemu::modbus
