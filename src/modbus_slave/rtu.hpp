#pragma once
// Modbus RTU on a serial line seat: frames delimited by the t3.5 silence and checked by their
// CRC (modbus/rtu_framer.hpp), answered as RTU frames (modbus/rtu_frame.hpp), the request routed
// by the line's unit table.

#include <array>
#include <memory>

#include "modbus/rtu_framer.hpp"
#include "plcemu/listener/protocol.hpp"

namespace plcemu::modbus_slave {

/// The Modbus RTU protocol of one serial line.
class ModbusRtu final : public listener::SerialProtocol {
public:
    /// Serves the PLCs of `setup` on a line with its settings.
    explicit ModbusRtu(listener::ProtocolSetup setup);

    std::span<const std::uint8_t> receive(std::span<const std::uint8_t> bytes,
                                          Clock::time_point now) noexcept override;
    std::span<const std::uint8_t> expire(Clock::time_point now) noexcept override;
    std::optional<Clock::time_point> deadline() const noexcept override;
    void clear() noexcept override { framer_.clear(); }
    listener::UnitTable& units() noexcept override { return units_; }
    std::string summary() const override;

    /// Answers one frame the framer ended (address, PDU, CRC).
    std::span<const std::uint8_t> serve(const modbus::RtuFrame& frame) noexcept;
    /// What the framer saw.
    const modbus::RtuFramerStats& stats() const noexcept { return framer_.stats(); }

private:
    listener::UnitTable units_;
    std::string device_;
    modbus::RtuFramer framer_;
    std::array<std::uint8_t, modbus::RtuFramer::kMaxFrame> reply_{};
};

/// Makes the protocol for a serial line (listener::ProtocolKind).
std::unique_ptr<listener::SerialProtocol> make_rtu(listener::ProtocolSetup setup);

}  // namespace plcemu::modbus_slave
