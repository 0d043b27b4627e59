#include "route.hpp"

#include <spdlog/spdlog.h>

#include <chrono>
#include <new>

namespace plcemu::modbus_slave {

std::size_t route(listener::UnitTable& units,
                  Addressing addressing,
                  std::uint8_t unit,
                  std::span<const std::uint8_t> pdu,
                  modbus::PduBuffer out) noexcept {
    if (addressing == Addressing::Rtu && unit == 0) {
        // A broadcast: every PLC on the line serves it, none answers.
        for (const listener::Seat& s : units.seats()) {
            s.dispatcher->answer({pdu, *s.unit, *s.station, true}, out);
        }
        units.count_broadcast();
        return 0;
    }
    const bool device_itself = addressing == Addressing::Tcp && (unit == 0 || unit == 0xFF);
    const listener::Hit hit = units.find(unit, device_itself);
    if (hit.seat == nullptr) {
        // On an RS-485 line a frame for another station is none of ours: silence.
        if (addressing == Addressing::Rtu) return 0;
        const bool refuse = units.unknown_unit() == listener::UnknownUnit::Refuse;
        spdlog::debug("modbus: unit {} is no PLC's on this listener{}", unit,
                      refuse ? ": exception 0Bh" : "");
        if (!refuse) return 0;
        return modbus::exception_pdu(pdu[0], modbus::Status::GatewayTargetFailed, out);
    }
    modbus::Unit& target = hit.simulator ? *hit.seat->simulator : *hit.seat->unit;
    const std::size_t n = hit.seat->dispatcher->answer({pdu, target, hit.answer_as, false}, out);
    if (hit.seat->traffic != nullptr && units.serving() != nullptr) {
        try {
            record(*hit.seat->traffic, *units.serving(), unit, hit.simulator, pdu,
                   std::span<const std::uint8_t>(out.data(), n));
        } catch (const std::bad_alloc&) {
            // The request is answered all the same; only its line in the traffic is lost.
        }
    }
    return n;
}

void record(listener::Traffic& traffic,
            const listener::Client& client,
            std::uint8_t unit,
            bool simulator,
            std::span<const std::uint8_t> pdu,
            std::span<const std::uint8_t> reply) {
    listener::Exchange e;
    e.at = std::chrono::system_clock::now();
    e.client = client.id;
    e.protocol = client.protocol;
    e.unit = unit;
    e.simulator = simulator;
    e.function = pdu[0];
    if (reply.size() >= 2 && (reply[0] & 0x80) != 0) e.error = reply[1];
    const auto be16 = [&](std::size_t at) {
        return static_cast<std::uint16_t>(pdu[at] << 8 | pdu[at + 1]);
    };
    if (pdu.size() >= 5) {
        e.address = be16(1);
        switch (pdu[0]) {
            case 0x01:
            case 0x02:
            case 0x03:
            case 0x04:
            case 0x0F:
            case 0x10:
            case 0x17:
                e.count = be16(3);
                break;
            case 0x05:
            case 0x06:
            case 0x16:
                e.count = 1;
                break;
            default:
                e.address = 0;
                break;
        }
    }
    traffic.record(client, e);
}

}  // namespace plcemu::modbus_slave
