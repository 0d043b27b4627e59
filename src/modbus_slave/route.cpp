#include "route.hpp"

#include <spdlog/spdlog.h>

#include <array>
#include <chrono>
#include <new>

namespace plcemu::modbus_slave {

namespace {

std::uint16_t be16(std::span<const std::uint8_t> pdu, std::size_t at) {
    return static_cast<std::uint16_t>(pdu[at] << 8 | pdu[at + 1]);
}

}  // namespace

std::array<Reach, 2> reach(std::span<const std::uint8_t> pdu) noexcept {
    std::array<Reach, 2> r{};
    if (pdu.size() < 5) return r;
    using modbus::Table;
    const auto at = [&](Table t, std::uint16_t count) { return Reach{t, be16(pdu, 1), count}; };
    switch (pdu[0]) {
        case 0x01:
            r[0] = at(Table::Coils, be16(pdu, 3));
            break;
        case 0x02:
            r[0] = at(Table::DiscreteInputs, be16(pdu, 3));
            break;
        case 0x03:
            r[0] = at(Table::HoldingRegisters, be16(pdu, 3));
            break;
        case 0x04:
            r[0] = at(Table::InputRegisters, be16(pdu, 3));
            break;
        case 0x05:
            r[0] = at(Table::Coils, 1);
            break;
        case 0x0F:
            r[0] = at(Table::Coils, be16(pdu, 3));
            break;
        case 0x06:
        case 0x16:
            r[0] = at(Table::HoldingRegisters, 1);
            break;
        case 0x10:
            r[0] = at(Table::HoldingRegisters, be16(pdu, 3));
            break;
        case 0x17:
            r[0] = at(Table::HoldingRegisters, be16(pdu, 3));
            if (pdu.size() >= 9) r[1] = Reach{Table::HoldingRegisters, be16(pdu, 5), be16(pdu, 7)};
            break;
        default:
            break;
    }
    return r;
}

namespace {

// What the PLC's communication faults make of the request (docs/communication-faults.md); the
// simulator unit is never judged.
listener::Verdict judge(listener::UnitTable& units,
                        const listener::Hit& hit,
                        std::uint8_t unit,
                        std::span<const std::uint8_t> pdu) noexcept {
    listener::CommFaults* faults = hit.seat->faults;
    if (hit.simulator || faults == nullptr || !faults->active()) return {};
    listener::Asked a;
    a.unit = unit;
    a.function = pdu[0];
    if (faults->settings().devices) {
        const auto r = reach(pdu);
        const auto devices = [&](const Reach& x) -> std::optional<image::Range> {
            if (x.count == 0) return std::nullopt;
            return hit.seat->unit->devices(x.table, x.address, x.count);
        };
        a.devices = devices(r[0]);
        a.also = devices(r[1]);
    }
    if (const listener::Client* c = units.serving()) {
        a.client = c->id;
        a.carrier = c->carrier;
    }
    return faults->judge(a);
}

}  // namespace

std::size_t route(listener::UnitTable& units,
                  Addressing addressing,
                  std::uint8_t unit,
                  std::span<const std::uint8_t> pdu,
                  modbus::PduBuffer out) noexcept {
    if (addressing == Addressing::Rtu && unit == 0) {
        // A broadcast: every PLC on the line serves it, none answers. An offline PLC or one that
        // refuses the request serves nothing.
        for (const listener::Seat& s : units.seats()) {
            if (s.faults != nullptr && s.faults->active()) {
                const listener::Hit self{&s, false, 0};
                if (judge(units, self, 0, pdu).kind != listener::Verdict::Kind::Serve) continue;
            }
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
    const listener::Verdict v = judge(units, hit, unit, pdu);
    if (v.kind == listener::Verdict::Kind::Silent) return 0;
    modbus::Unit& target = hit.simulator ? *hit.seat->simulator : *hit.seat->unit;
    const std::size_t n =
        v.kind == listener::Verdict::Kind::Exception
            ? modbus::exception_pdu(pdu[0], static_cast<modbus::Status>(v.code), out)
            : hit.seat->dispatcher->answer({pdu, target, hit.answer_as, false}, out);
    if (hit.seat->traffic != nullptr && units.serving() != nullptr) {
        try {
            record(*hit.seat->traffic, *units.serving(), unit, hit.simulator, pdu,
                   std::span<const std::uint8_t>(out.data(), n));
        } catch (const std::bad_alloc&) {
            // The request is answered all the same; only its line in the traffic is lost.
        }
    }
    units.fate() = v.fate;
    return v.drop ? 0 : n;
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
    // A function without a range reaches {0, 0}, which the list shows as none.
    const auto [r, w] = reach(pdu);
    e.address = r.address;
    e.count = r.count;
    e.write_address = w.address;
    e.write_count = w.count;
    traffic.record(client, e);
}

}  // namespace plcemu::modbus_slave
