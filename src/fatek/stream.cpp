#include "stream.hpp"

#include "frame.hpp"
#include "serve.hpp"
#include "split.hpp"

namespace plcemu::fatek {

FatekStream::FatekStream(listener::ProtocolSetup setup) {
    // Unknown stations are always silent here: the unknown-unit policy is Modbus's.
    units_.assign(std::move(setup.seats));
    units_.set_unknown_unit(listener::UnknownUnit::Silent);
    units_.set_read_only(setup.read_only);
}

std::size_t FatekStream::max_frame() const noexcept { return kMaxFrame; }

listener::Split FatekStream::split(std::span<const std::uint8_t> buffered) const noexcept {
    return split_stream(buffered);
}

std::size_t FatekStream::answer(std::span<const std::uint8_t> frame,
                                std::span<std::uint8_t> out) noexcept {
    // The frame is checked whole: split() may have cut off bytes to skip, and a datagram is
    // whatever the sender put in it.
    return serve(units_, frame, out);
}

std::unique_ptr<listener::StreamProtocol> make_stream(listener::ProtocolSetup setup) {
    return std::make_unique<FatekStream>(std::move(setup));
}

std::unique_ptr<listener::StreamProtocol> make_datagram(listener::ProtocolSetup setup) {
    return std::make_unique<FatekStream>(std::move(setup));
}

}  // namespace plcemu::fatek
