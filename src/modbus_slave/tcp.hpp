#pragma once
// Modbus TCP on a TCP listener seat: MBAP frames in, MBAP frames out (modbus/mbap.hpp), the
// request routed by the listener's unit table.

#include <memory>

#include "plcemu/listener/protocol.hpp"

namespace plcemu::modbus_slave {

/// The Modbus TCP protocol of one listener.
class ModbusTcp final : public listener::StreamProtocol {
public:
    /// Serves the PLCs of `setup`.
    explicit ModbusTcp(listener::ProtocolSetup setup);

    std::size_t max_frame() const noexcept override;
    listener::Split split(std::span<const std::uint8_t> buffered) const noexcept override;
    std::size_t answer(std::span<const std::uint8_t> frame,
                       std::span<std::uint8_t> out) noexcept override;
    listener::UnitTable& units() noexcept override { return units_; }

private:
    listener::UnitTable units_;
};

/// Makes the protocol for a listener (listener::ProtocolKind).
std::unique_ptr<listener::StreamProtocol> make_tcp(listener::ProtocolSetup setup);

}  // namespace plcemu::modbus_slave
