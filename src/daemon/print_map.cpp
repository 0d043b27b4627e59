#include "print_map.hpp"

#include <cstdio>
#include <string>
#include <vector>

#include "plcemu/modbus/address_map.hpp"

namespace plcemu::daemon {

namespace {

using modbus::Table;

struct Row {
    std::string table, five, six, wire, fatek, codes, access;
};

std::string padded(unsigned v, int width) {
    char buf[16];
    std::snprintf(buf, sizeof buf, "%0*u", width, v);
    return buf;
}

const char* table_name(Table t) {
    switch (t) {
        case Table::Coils: return "coils";
        case Table::DiscreteInputs: return "discrete inputs";
        case Table::HoldingRegisters: return "holding registers";
        case Table::InputRegisters: return "input registers";
    }
    return "?";
}

// The manual numbers from 1: coil n is 0xxxx, holding register n is 4xxxx.
std::string manual_number(Table t, unsigned wire, int digits) {
    const unsigned prefix = t == Table::HoldingRegisters ? 4 : 0;
    const unsigned scale = digits == 5 ? 10000 : 100000;
    return padded(prefix * scale + wire + 1, digits);
}

std::string access_of(const modbus::AddressMap& map, const image::Range& r) {
    std::string ro;
    for (const auto& p : map.read_only()) {
        if (p.contains(r)) return "read-only";
        if (!p.overlaps(r)) continue;
        if (!ro.empty()) ro += ' ';
        ro += image::format_range(p);
    }
    if (ro.empty()) return "read/write";
    std::string access = "read/write except ";
    access += ro;
    access += " (read-only)";
    return access;
}

std::vector<Row> rows_of(const config::Config& config) {
    const auto& map = modbus::fbs_map();
    std::vector<Row> rows;
    for (const auto& r : map.rows()) {
        const unsigned first = r.wire_start;
        const unsigned last = r.wire_start + r.count - 1u;
        rows.push_back({table_name(r.table),
                        manual_number(r.table, first, 5) + "-" + manual_number(r.table, last, 5),
                        manual_number(r.table, first, 6) + "-" + manual_number(r.table, last, 6),
                        std::to_string(first) + "-" + std::to_string(last), r.label, r.codes,
                        access_of(map, r.devices)});
    }
    if (config.simulator.unit != 0) {
        const std::string unit = "unit " + std::to_string(config.simulator.unit);
        rows.push_back({"holding registers (" + unit + ")", "40001-40005", "400001-400005",
                        "0-4", "simulator: time scale, freeze, step, simulated time (s, 32-bit)",
                        "03 06 16", "read/write except 3-4 (read-only)"});
        rows.push_back({"holding registers (" + unit + ")", "40101-40420", "400101-400420",
                        "100-419",
                        "simulator channel c at 100+10c: faults, ambient, K, tau, dead time, noise, "
                        "true temperature, heater power",
                        "03 06 16", "read/write except +6,+7 (read-only)"});
    }
    return rows;
}

}  // namespace

void print_map(std::ostream& out, const config::Config& config, bool csv) {
    const auto rows = rows_of(config);
    if (csv) {
        out << "table,modbus_5digit,modbus_6digit,wire,fatek,function_codes,access\n";
        auto q = [](const std::string& s) { return "\"" + s + "\""; };
        for (const auto& r : rows) {
            out << q(r.table) << ',' << r.five << ',' << r.six << ',' << r.wire << ',' << q(r.fatek)
                << ',' << r.codes << ',' << q(r.access) << '\n';
        }
        return;
    }
    out << "Modbus map, profile " << image::profile_name(config.profile) << " (" << config.model
        << "), station " << int(config.station) << " and unit 255\n";
    out << "Wire address = manual number - 1.\n\n";
    char line[512];
    std::snprintf(line, sizeof line, "%-28s %-13s %-15s %-10s %-54s %-15s %s\n", "table",
                  "5-digit", "6-digit", "wire", "FATEK", "codes", "access");
    out << line;
    for (const auto& r : rows) {
        std::snprintf(line, sizeof line, "%-28s %-13s %-15s %-10s %-54s %-15s %s\n",
                      r.table.c_str(), r.five.c_str(), r.six.c_str(), r.wire.c_str(),
                      r.fatek.c_str(), r.codes.c_str(), r.access.c_str());
        out << line;
    }
    out << "\nMaps held in the image (FATEK user remap, manual 13-50/51):\n";
    for (const auto& n : modbus::fbs_map().dynamic_notes()) out << "  " << n << '\n';
    out << "Any other address: exception 02. Unsupported function codes: exception 01.\n";
}

}  // namespace plcemu::daemon
