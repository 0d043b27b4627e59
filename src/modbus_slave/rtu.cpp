#include "rtu.hpp"

#include <spdlog/spdlog.h>

#include "modbus/rtu_frame.hpp"
#include "route.hpp"

namespace plcemu::modbus_slave {

namespace {

const char* verdict_name(modbus::RtuVerdict v) {
    switch (v) {
        case modbus::RtuVerdict::Ok:
            return "ok";
        case modbus::RtuVerdict::BadCrc:
            return "bad CRC";
        case modbus::RtuVerdict::TooShort:
            return "too short";
        case modbus::RtuVerdict::TooLong:
            return "too long";
        case modbus::RtuVerdict::Gap:
            return "pause longer than t1.5 inside the frame";
    }
    return "?";
}

}  // namespace

ModbusRtu::ModbusRtu(listener::ProtocolSetup setup)
    : device_(setup.line.device),
      framer_(modbus::RtuTiming::for_line(
          setup.line.baud, setup.line.parity, setup.line.data_bits, setup.line.stop_bits)) {
    units_.assign(std::move(setup.seats));
    units_.set_unknown_unit(setup.unknown_unit);
}

std::span<const std::uint8_t> ModbusRtu::receive(std::span<const std::uint8_t> bytes,
                                                 Clock::time_point now) noexcept {
    // The silence before these bytes may have ended the previous frame even if its deadline has
    // not been seen yet (the loop was busy): that frame is answered.
    if (auto f = framer_.receive(bytes, now)) return serve(*f);
    return {};
}

std::span<const std::uint8_t> ModbusRtu::expire(Clock::time_point now) noexcept {
    if (auto f = framer_.expire(now)) return serve(*f);
    return {};
}

std::optional<listener::SerialProtocol::Clock::time_point> ModbusRtu::deadline() const noexcept {
    return framer_.deadline();
}

std::span<const std::uint8_t> ModbusRtu::serve(const modbus::RtuFrame& f) noexcept {
    if (f.verdict != modbus::RtuVerdict::Ok || f.bytes.size() < modbus::kMinRtuFrame) {
        spdlog::debug("rtu: {}: {}-byte frame dropped: {}", device_, f.bytes.size(),
                      verdict_name(f.verdict));
        return {};
    }
    // The handler writes the reply PDU where the frame holds it: no copy, nothing cleared first.
    const modbus::PduBuffer pdu(modbus::rtu_pdu_room(reply_).data(), modbus::kMaxPdu);
    const std::size_t n =
        route(units_, Addressing::Rtu, modbus::rtu_address(f.bytes), modbus::rtu_pdu(f.bytes), pdu);
    if (n == 0) return {};
    const std::size_t size = modbus::frame_rtu(modbus::rtu_address(f.bytes), n, reply_);
    listener::Fate& fate = units_.fate();
    if (fate.garble == listener::Garble::Crc) reply_[size - 1] ^= 0xFF;
    // A pause between t1.5 and t3.5: the frame is broken, yet not two frames (Modbus over
    // serial line, 2.5.1.1).
    const modbus::RtuTiming& t = framer_.timing();
    const auto gap = std::chrono::duration_cast<std::chrono::microseconds>((t.t15 + t.t35) / 2);
    return {reply_.data(), listener::cut_or_pause(fate, size, gap)};
}

std::string ModbusRtu::summary() const {
    const modbus::RtuFramerStats& st = framer_.stats();
    return std::to_string(st.frames) +
           " frames with a good CRC; dropped: " + std::to_string(st.bad_crc) + " bad CRC, " +
           std::to_string(st.gaps) + " t1.5 pauses, " + std::to_string(st.too_short) +
           " too short, " + std::to_string(st.too_long) + " too long";
}

std::unique_ptr<listener::SerialProtocol> make_rtu(listener::ProtocolSetup setup) {
    return std::make_unique<ModbusRtu>(std::move(setup));
}

}  // namespace plcemu::modbus_slave
