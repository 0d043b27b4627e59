#include "route.hpp"

#include <spdlog/spdlog.h>

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
    return hit.seat->dispatcher->answer({pdu, target, hit.answer_as, false}, out);
}

}  // namespace plcemu::modbus_slave
