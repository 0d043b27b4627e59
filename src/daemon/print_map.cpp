#include "print_map.hpp"

#include <cstdio>
#include <string>
#include <vector>

#include "plcemu/daemon/plc.hpp"
#include "plcemu/fatek/device_name.hpp"
#include "plcemu/modbus/address_map.hpp"
#include "plcemu/profiles/profile.hpp"
#include "simulator/simulator_unit.hpp"

namespace plcemu::daemon {

namespace {

using modbus::Table;

struct Row {
    std::string table, five, six, wire, fatek, codes, access;
    std::string protocol_name;  // the devices as FATEK's protocol names them, "" for none
};

// "R00000-R04167": the first and last device of a map row as a FATEK master names them (the
// last one with a name: a 32-bit counter's high word has none); empty when the first has none.
std::string fatek_names(const image::Layout& layout, const modbus::MapRow& r) {
    const image::Range& d = r.devices;
    const std::uint32_t step = r.packed ? 16 : 1;
    std::string names = fatek::device_name(layout, d.area, d.start, r.packed);
    if (names.empty() || r.count <= 1) return names;
    for (std::uint32_t k = r.count; k-- > 1;) {
        const std::string last = fatek::device_name(layout, d.area, d.start + step * k, r.packed);
        if (last.empty()) continue;
        names += '-';
        names += last;
        break;
    }
    return names;
}

std::string padded(unsigned v, int width) {
    char buf[16];
    std::snprintf(buf, sizeof buf, "%0*u", width, v);
    return buf;
}

const char* table_name(Table t) {
    switch (t) {
        case Table::Coils:
            return "coils";
        case Table::DiscreteInputs:
            return "discrete inputs";
        case Table::HoldingRegisters:
            return "holding registers";
        case Table::InputRegisters:
            return "input registers";
    }
    return "?";
}

// The manuals number from 1: coil n is 0xxxx, discrete input 1xxxx, input register 3xxxx,
// holding register 4xxxx.
std::string manual_number(Table t, unsigned wire, int digits) {
    unsigned prefix = 0;
    if (t == Table::DiscreteInputs) prefix = 1;
    if (t == Table::InputRegisters) prefix = 3;
    if (t == Table::HoldingRegisters) prefix = 4;
    const unsigned scale = digits == 5 ? 10000 : 100000;
    return padded(prefix * scale + wire + 1, digits);
}

std::string access_of(const modbus::AddressMap& map,
                      const modbus::MapRow& row,
                      const image::Naming& naming) {
    const image::Range& r = row.devices;
    // Discrete inputs and input registers are read-only by their function codes.
    if (row.read_only || row.table == Table::DiscreteInputs || row.table == Table::InputRegisters)
        return "read-only";
    std::string ro;
    for (const auto& p : map.read_only()) {
        if (p.contains(r)) return "read-only";
        if (!p.overlaps(r)) continue;
        if (!ro.empty()) ro += ' ';
        ro += naming.format_range(p);
    }
    if (ro.empty()) return "read/write";
    std::string access = "read/write except ";
    access += ro;
    access += " (read-only)";
    return access;
}

// `fatek`: the rows name their devices as FATEK's protocol does too.
std::vector<Row> rows_of(const config::Config& config, const modbus::AddressMap& map, bool fatek) {
    const profiles::Profile& profile = profiles::of(config);
    const image::Naming& naming = profile.naming();
    const image::Layout layout = profile.layout();
    std::vector<Row> rows;
    for (const auto& r : map.rows()) {
        const unsigned first = r.wire_start;
        const unsigned last = r.wire_start + r.count - 1u;
        // 5-digit numbers end at x9999 (wire 9998): a row beyond has none (the VB's 3000h rows).
        const std::string five =
            last < 9999 ? manual_number(r.table, first, 5) + "-" + manual_number(r.table, last, 5)
                        : "-";
        rows.push_back({table_name(r.table), five,
                        manual_number(r.table, first, 6) + "-" + manual_number(r.table, last, 6),
                        std::to_string(first) + "-" + std::to_string(last), r.label, r.codes,
                        access_of(map, r, naming), fatek ? fatek_names(layout, r) : std::string()});
    }
    if (config.simulator.unit != 0) {
        // The simulator-control unit (docs/simulator-and-plant.md): one row per register
        // (channel words as 100+10c).
        const std::string table =
            "holding registers (unit " + std::to_string(config.simulator.unit) + ")";
        const std::string rw = "03 06 16 22 23";
        const std::string ro = "03 23";
        struct Sim {
            unsigned wire;
            const char* what;
            bool writable;
        };
        const Sim fixed[] = {
            {0, "simulator: time scale, 1-10000 simulated s per real s", true},
            {1, "simulator: freeze, 1 = scans stopped", true},
            {2,
             "simulator: step, write N to queue N scans (0 cancels); reads the scans still queued",
             true},
            {3, "simulator: simulated time, s, low word", false},
            {4, "simulator: simulated time, s, high word", false},
        };
        for (const auto& f : fixed) {
            rows.push_back({table, manual_number(Table::HoldingRegisters, f.wire, 5),
                            manual_number(Table::HoldingRegisters, f.wire, 6),
                            std::to_string(f.wire), f.what, f.writable ? rw : ro,
                            f.writable ? "read/write" : "read-only", ""});
        }
        // The communication faults (docs/communication-faults.md), as the unit lists them.
        for (const auto& t : simulator::register_tags()) {
            if (t.name.rfind("sim.comm.", 0) != 0) continue;
            const bool w = simulator::SimulatorUnit::writable(t.wire);
            rows.push_back({table, manual_number(Table::HoldingRegisters, t.wire, 5),
                            manual_number(Table::HoldingRegisters, t.wire, 6),
                            std::to_string(t.wire), t.description, w ? rw : ro,
                            w ? "read/write" : "read-only", ""});
        }
        const Sim channel[] = {
            {0,
             "channel c (0-31): faults b0 sensor broken, b1 heater open, b2 heater shorted, "
             "b3 reading frozen",
             true},
            {1, "channel c: ambient, 0.1 C, signed", true},
            {2, "channel c: K full-power rise, 0.1 C", true},
            {3, "channel c: tau, s", true},
            {4, "channel c: dead time, s", true},
            {5, "channel c: noise sigma, 0.01 C", true},
            {6, "channel c: true temperature, 0.1 C, signed", false},
            {7, "channel c: heater power, 0.1 % (mean of the last 8 s)", false},
            {8, "channel c: RTD lead resistance, 0.01 ohm, 0-10000", true},
            {9, "channel c: reserved (reads 0)", false},
        };
        for (const auto& f : channel) {
            const unsigned wire = 100 + f.wire;
            rows.push_back({table, manual_number(Table::HoldingRegisters, wire, 5) + "+10c",
                            manual_number(Table::HoldingRegisters, wire, 6) + "+10c",
                            std::to_string(wire) + "+10c", f.what, f.writable ? rw : ro,
                            f.writable ? "read/write" : "read-only", ""});
        }
    }
    return rows;
}

}  // namespace

void print_map(std::ostream& out, const config::Config& config, bool csv) {
    const profiles::Profile& profile = profiles::of(config);
    const std::unique_ptr<modbus::AddressMap> own = map_of(config);
    const modbus::AddressMap& map = own ? *own : profile.map();
    // A family that speaks FATEK's protocol gets a column of the names its frames use.
    const bool fatek = profile.speaks("fatek");
    const auto rows = rows_of(config, map, fatek);
    // The device column is named after the vendor whose names it holds ("fatek", "vigor").
    std::string vendor(profile.vendor());
    for (char& c : vendor) c = static_cast<char>(c >= 'A' && c <= 'Z' ? c - 'A' + 'a' : c);
    auto q = [](const std::string& s) { return "\"" + s + "\""; };
    // A PLC of a `plcs:` list: its rows say which ("kiln", "plcs[1]") in a first column, as
    // --export-tags does.
    const std::string id = config::plc_id(config);
    const bool entry = !id.empty();
    if (csv) {
        out << (entry ? "plc," : "") << "table,modbus_5digit,modbus_6digit,wire," << vendor
            << ",function_codes,access" << (fatek ? ",fatek_protocol" : "") << "\n";
        for (const auto& r : rows) {
            if (entry) out << q(id) << ',';
            out << q(r.table) << ',' << r.five << ',' << r.six << ',' << r.wire << ',' << q(r.fatek)
                << ',' << r.codes << ',' << q(r.access);
            if (fatek) out << ',' << q(r.protocol_name);
            out << '\n';
        }
        return;
    }
    if (entry) {
        out << config.label << ", tcp ";
        if (config.modbus.tcp.enabled) {
            out << config.modbus.tcp.bind << ':' << config.modbus.tcp.port;
        } else {
            out << "off";
        }
        if (config.modbus.rtu) out << ", rtu " << config.modbus.rtu->device;
        out << ":\n";
    }
    out << "Modbus map, profile " << config.profile << " (" << profile.vendor() << ' '
        << config.model << "), station " << int(config.station) << " and unit 255\n";
    out << "Wire address = manual number - 1.";
    if (own) out << " The map is the config's modbus.map, not the profile's default.";
    out << "\n\n";
    char line[640];
    // The FATEK protocol's names come before the access column, whose width varies.
    const char* format = fatek ? "%-28s %-13s %-15s %-11s %-54s %-15s %-16s %s\n"
                               : "%-28s %-13s %-15s %-11s %-54s %-15s %s%s\n";
    std::snprintf(line, sizeof line, format, "table", "5-digit", "6-digit", "wire",
                  std::string(profile.vendor()).c_str(), "codes", fatek ? "FATEK protocol" : "",
                  "access");
    out << line;
    for (const auto& r : rows) {
        std::snprintf(line, sizeof line, format, r.table.c_str(), r.five.c_str(), r.six.c_str(),
                      r.wire.c_str(), r.fatek.c_str(), r.codes.c_str(), r.protocol_name.c_str(),
                      r.access.c_str());
        out << line;
    }
    const auto notes = map.dynamic_notes();
    if (!notes.empty()) out << "\nMaps held in the image:\n";
    for (const auto& n : notes) out << "  " << n << '\n';
    out << "Any other address: exception 02. Unsupported function codes: exception 01.\n";
}

}  // namespace plcemu::daemon
