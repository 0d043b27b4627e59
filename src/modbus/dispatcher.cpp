#include "plcemu/modbus/dispatcher.hpp"

#include <spdlog/spdlog.h>

#include <array>
#include <cstring>

#include "crc.hpp"
#include "plcemu/modbus/function_handler.hpp"

namespace plcemu::modbus {

Dispatcher::Dispatcher(Unit& plc, const std::uint8_t& station, Identity identity)
    : plc_(plc),
      station_(station),
      identity_(std::move(identity)),
      functions_(standard_functions()) {}

Dispatcher::~Dispatcher() = default;

void Dispatcher::set_simulator(Unit* sim, std::uint8_t unit_id) {
    sim_ = unit_id != 0 ? sim : nullptr;
    sim_unit_ = unit_id;
}

std::size_t Dispatcher::serve_tcp(std::span<const std::uint8_t> adu, ReplyBuffer out) noexcept {
    return serve(Transport::Tcp, adu, out);
}

std::size_t Dispatcher::serve_rtu(std::span<const std::uint8_t> frame, ReplyBuffer out) noexcept {
    return serve(Transport::Rtu, frame, out);
}

namespace {

// Frames a reply PDU like the request it answers (MBAP header, or address and CRC), into `out`.
// Returns the length.
std::size_t frame_pdu(Transport t,
                      const std::uint8_t* req,
                      const std::uint8_t* pdu,
                      std::size_t n,
                      ReplyBuffer out) noexcept {
    std::size_t len = 0;
    if (t == Transport::Tcp) {
        out[0] = req[0];
        out[1] = req[1];
        out[2] = 0;
        out[3] = 0;
        out[4] = static_cast<std::uint8_t>((n + 1) >> 8);
        out[5] = static_cast<std::uint8_t>((n + 1) & 0xFF);
        out[6] = req[6];
        len = 7;
    } else {
        out[0] = req[0];
        len = 1;
    }
    std::memcpy(out.data() + len, pdu, n);
    len += n;
    if (t == Transport::Rtu) {
        const std::uint16_t crc = crc16(out.data(), len);
        out[len++] = static_cast<std::uint8_t>(crc & 0xFF);
        out[len++] = static_cast<std::uint8_t>(crc >> 8);
    }
    return len;
}

}  // namespace

std::size_t exception_reply(Transport t,
                            std::span<const std::uint8_t> adu,
                            Status s,
                            ReplyBuffer out) noexcept {
    const std::size_t header = t == Transport::Tcp ? 7 : 1;
    // Set the high bit rather than add 80h as modbus_reply_exception does, which would wrap
    // a function code of 80h or more to a normal-looking reply.
    const std::array<std::uint8_t, 2> e{static_cast<std::uint8_t>(adu[header] | 0x80),
                                        static_cast<std::uint8_t>(s)};
    return frame_pdu(t, adu.data(), e.data(), e.size(), out);
}

std::size_t Dispatcher::serve(Transport t,
                              std::span<const std::uint8_t> adu,
                              ReplyBuffer reply) noexcept {
    const std::size_t header = t == Transport::Tcp ? 7 : 1;
    const std::size_t trailer = t == Transport::Rtu ? 2 : 0;
    if (adu.size() < header + 1 + trailer) {
        ++stats_.ignored;
        return 0;
    }
    const std::uint8_t* req = adu.data();
    const std::uint8_t unit = req[header - 1];
    const std::span<const std::uint8_t> pdu = adu.subspan(header, adu.size() - header - trailer);
    const std::uint8_t fc = pdu[0];
    const bool broadcast = t == Transport::Rtu && unit == 0;

    auto exception = [&](Status s) -> std::size_t {
        // Refused requests are what a SCADA integrator hunts for; debug keeps them off by default.
        spdlog::debug("modbus: unit {} function {:02X}h address {} refused: exception {:02X}h{}",
                      unit, fc, pdu.size() >= 3 ? be16(pdu.data() + 1) : 0,
                      static_cast<unsigned>(s), broadcast ? " (broadcast, not sent)" : "");
        if (broadcast) return 0;  // a broadcast is never answered
        ++stats_.exceptions;
        return exception_reply(t, adu, s, reply);
    };

    Unit* target = nullptr;
    // Over TCP, 0 and 255 address the device itself (Modbus TCP implementation guide §4.4.1.2:
    // clients such as Node-RED's fall back to 0); over RTU, 0 is the broadcast address.
    if (unit == station_ || broadcast || (t == Transport::Tcp && (unit == 0xFF || unit == 0))) {
        target = &plc_;
    } else if (sim_ != nullptr && unit == sim_unit_) {
        target = sim_;
    } else {
        if (t == Transport::Tcp && unknown_unit_ == UnknownUnitPolicy::Exception) {
            ++stats_.requests;
            return exception(Status::GatewayTargetFailed);
        }
        ++stats_.ignored;
        return 0;
    }

    ++stats_.requests;
    const FunctionHandler handler = fc < functions_.size() ? functions_[fc] : nullptr;
    if (handler == nullptr) return exception(Status::IllegalFunction);
    const FunctionRequest request{pdu, *target, target == &plc_ ? station_ : unit, broadcast,
                                  identity_};
    std::array<std::uint8_t, kMaxPdu> out;  // a handler writes what it returns
    const FunctionReply r = handler(request, out);
    if (r.status != Status::Ok) return exception(r.status);
    if (r.size == 0 || broadcast) return 0;
    return frame_pdu(t, req, out.data(), r.size, reply);
}

void Dispatcher::set_function(std::uint8_t fc, FunctionHandler handler) {
    if (fc < functions_.size()) functions_[fc] = handler;
}

}  // namespace plcemu::modbus
