#include "tcp.hpp"

#include "modbus/mbap.hpp"
#include "route.hpp"

namespace plcemu::modbus_slave {

ModbusTcp::ModbusTcp(listener::ProtocolSetup setup) {
    units_.assign(std::move(setup.seats));
    units_.set_unknown_unit(setup.unknown_unit);
}

std::size_t ModbusTcp::max_frame() const noexcept { return modbus::kMaxTcpAdu; }

listener::Split ModbusTcp::split(std::span<const std::uint8_t> buffered) const noexcept {
    const modbus::MbapFrame f = modbus::next_mbap_frame(buffered);
    switch (f.status) {
        case modbus::MbapStatus::Frame:
            return {listener::Cut::Frame, f.size};
        case modbus::MbapStatus::Bad:
            // A bad header closes the connection (docs/profile-fbs.md, "Modbus map").
            return {listener::Cut::Bad, 0, "bad MBAP header"};
        case modbus::MbapStatus::Incomplete:
            break;
    }
    return {};
}

std::size_t ModbusTcp::answer(std::span<const std::uint8_t> frame,
                              std::span<std::uint8_t> out) noexcept {
    // split() vouched for the header (a length of 2 or more: a function code is there); a frame
    // from elsewhere is checked.
    if (frame.size() < modbus::kMbapPrefix + 2 || out.size() < modbus::kMaxTcpAdu) return 0;
    // The handler writes the reply PDU where the frame holds it: no copy, nothing cleared first.
    const modbus::PduBuffer pdu(modbus::mbap_pdu_room(out).data(), modbus::kMaxPdu);
    const std::size_t n =
        route(units_, Addressing::Tcp, modbus::mbap_unit(frame), modbus::mbap_pdu(frame), pdu);
    if (n == 0) return 0;
    return modbus::frame_mbap(modbus::mbap_transaction(frame), modbus::mbap_unit(frame), n, out);
}

std::unique_ptr<listener::StreamProtocol> make_tcp(listener::ProtocolSetup setup) {
    return std::make_unique<ModbusTcp>(std::move(setup));
}

}  // namespace plcemu::modbus_slave
