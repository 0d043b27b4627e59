#include "http/traffic.hpp"

#include <optional>

#include "http/plcs.hpp"
#include "plcemu/modbus/unit.hpp"

namespace plcemu::http {

namespace {

// The table a Modbus function reaches.
std::optional<modbus::Table> table_of(std::uint8_t fc) {
    switch (fc) {
        case 0x01:
        case 0x05:
        case 0x0F:
            return modbus::Table::Coils;
        case 0x02:
            return modbus::Table::DiscreteInputs;
        case 0x03:
        case 0x06:
        case 0x10:
        case 0x16:
        case 0x17:
            return modbus::Table::HoldingRegisters;
        case 0x04:
            return modbus::Table::InputRegisters;
        default:
            return std::nullopt;
    }
}

// Text is appended piece by piece in this file: GCC 12 at -O2 takes `"literal" +
// std::to_string(...)` for an overlapping copy (-Wrestrict, a false positive that -Werror would
// make fatal).
std::string gone(std::uint64_t client) {
    std::string s = "#";
    s += std::to_string(client);
    s += " (gone)";
    return s;
}

Json exchange_json(const listener::Seat& plc, const listener::Exchange& e) {
    const std::string_view peer = plc.traffic->peer(e.client);
    Json j{{"at", wall_time(e.at)},
           {"client", peer.empty() ? gone(e.client) : std::string(peer)},
           {"protocol", std::string(e.protocol)},
           {"unit", e.unit},
           {"function", hex2(e.function) + "h"},
           {"error", e.error == 0 ? std::string() : hex2(e.error) + "h"}};
    std::string devices;
    const bool modbus = e.protocol.rfind("modbus", 0) == 0;
    const auto table = modbus ? table_of(e.function) : std::nullopt;
    // The devices of `count` elements of the function's table from `address`.
    const auto range = [&](std::uint16_t address, std::uint16_t count) {
        std::string d;
        if (count == 0) {
            d = "nothing";
        } else if (e.simulator) {
            // The simulator unit has registers only (docs/simulator.md).
            d = "simulator unit, register ";
            d += std::to_string(address);
            if (count > 1) {
                d += '+';
                d += std::to_string(count - 1);
            }
        } else if (const auto r = plc.unit->devices(*table, address, count)) {
            d = plc.naming->format_range(*r);
        } else {
            d = "address ";
            d += std::to_string(address);
            d += " (not mapped)";
        }
        return d;
    };
    if (!table || (e.simulator && *table != modbus::Table::HoldingRegisters) ||
        (!e.simulator && plc.unit == nullptr)) {
        if (modbus && e.simulator) devices = "simulator unit";
    } else if (e.function == 0x17) {
        // 17h reads one range and writes another, either of them maybe none.
        devices = "read ";
        devices += range(e.address, e.count);
        devices += ", write ";
        devices += range(e.write_address, e.write_count);
    } else {
        devices = range(e.address, e.count);  // "nothing" for a count of 0, as in 17h
    }
    j["devices"] = devices;
    return j;
}

}  // namespace

Response traffic(const Call& call, const listener::Seat& plc) {
    std::optional<Response> refused;
    const std::size_t count = count_param(call, 100, listener::Traffic::kKept, refused);
    if (refused) return *refused;
    Json clients = Json::array();
    Json exchanges = Json::array();
    if (plc.traffic != nullptr) {
        for (const auto& c : plc.traffic->clients()) clients.push_back(client_json(c));
        const auto all = plc.traffic->exchanges();
        const std::size_t from = all.size() > count ? all.size() - count : 0;
        for (std::size_t i = from; i < all.size(); ++i)
            exchanges.push_back(exchange_json(plc, all[i]));
    }
    return json(200, Json{{"clients", std::move(clients)}, {"exchanges", std::move(exchanges)}});
}

}  // namespace plcemu::http
