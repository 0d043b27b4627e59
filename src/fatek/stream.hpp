#pragma once
// FATEK on a TCP listener (frames cut from the stream, several may be pipelined) or a UDP one
// (one datagram, one frame) (docs/profile-fbs.md, "FATEK protocol").

#include <memory>

#include "plcemu/listener/protocol.hpp"

namespace plcemu::fatek {

/// The FATEK protocol of one TCP or UDP listener.
class FatekStream final : public listener::StreamProtocol {
public:
    /// Serves the PLCs of `setup`.
    explicit FatekStream(listener::ProtocolSetup setup);

    std::size_t max_frame() const noexcept override;
    listener::Split split(std::span<const std::uint8_t> buffered) const noexcept override;
    std::size_t answer(std::span<const std::uint8_t> frame,
                       std::span<std::uint8_t> out) noexcept override;
    listener::UnitTable& units() noexcept override { return units_; }

private:
    listener::UnitTable units_;
};

/// Makes the protocol for a TCP listener (listener::ProtocolKind).
std::unique_ptr<listener::StreamProtocol> make_stream(listener::ProtocolSetup setup);
/// Makes the protocol for a UDP listener (listener::ProtocolKind).
std::unique_ptr<listener::StreamProtocol> make_datagram(listener::ProtocolSetup setup);

}  // namespace plcemu::fatek
