#include "export_tags.hpp"

#include "hmi_tags.hpp"

#include <algorithm>
#include <iterator>
#include <cstdio>
#include <map>
#include <memory>
#include <string_view>
#include <tuple>
#include <utility>

#include "plcemu/daemon/plc.hpp"
#include "plcemu/fatek/device_name.hpp"
#include "plcemu/engine/tags.hpp"
#include "plcemu/image/utf8.hpp"
#include "plcemu/modbus/address_map.hpp"
#include "plcemu/profiles/profile.hpp"
#include "simulator/simulator_unit.hpp"

namespace plcemu::daemon {

namespace {

using image::Area;
using modbus::Table;

/// What the tags say of one device.
struct Meaning {
    std::vector<std::string> descriptions;  // in the order they were given, once each
    bool is_unsigned = false;               // some tag reads its word as bits or a code
};

/// Device → meaning; a counter value is keyed by its counter's first word.
using Meanings = std::map<std::pair<Area, std::uint32_t>, Meaning>;

/// Adds `tags` device by device: a tag of several devices gives each its ordinal ("[3]").
void add(Meanings& out,
         const engine::Tags& tags,
         const image::Naming& naming,
         const image::Layout& layout) {
    for (const auto& t : tags) {
        const image::Range& r = t.devices;
        std::vector<std::uint32_t> devices;  // the first word of each device the range holds
        for (std::uint32_t i = r.start; i < r.end(); ++i) {
            if (!layout.contains({r.area, i, 1})) continue;
            const std::uint32_t key =
                r.area == Area::CV ? naming.counter_word(naming.counter_of_word(i)) : i;
            if (devices.empty() || devices.back() != key) devices.push_back(key);
        }
        for (std::size_t k = 0; k < devices.size(); ++k) {
            Meaning& m = out[{r.area, devices[k]}];
            std::string d = t.description;
            if (devices.size() > 1) d += " [" + std::to_string(k) + "]";
            if (std::find(m.descriptions.begin(), m.descriptions.end(), d) == m.descriptions.end())
                m.descriptions.push_back(std::move(d));
            m.is_unsigned = m.is_unsigned || t.number == engine::Number::Unsigned;
        }
    }
}

std::string joined(const std::vector<std::string>& parts) {
    std::string s;
    for (const auto& p : parts) s += (s.empty() ? "" : "; ") + p;
    return s;
}

std::string where(const config::Position& p) {
    return p.file.str() + ":" + std::to_string(p.line) + ":" + std::to_string(p.column);
}

/// What the config itself says of devices: `init:` presets and the drives of the plant.
engine::Tags config_tags(const config::Config& config, const engine::Program& program) {
    engine::Tags t;
    for (const auto& e : config.init) {
        const auto n = static_cast<std::uint32_t>(e.values.size());
        const image::Range r{e.device.area, e.device.index, e.device.word_of_bits ? 16 * n : n};
        t.push_back({r, "preset by init: (" + where(e.pos) + ")"});
    }
    const plant::PlantSetup setup = plant_setup(config, engine::declarations_of(program));
    for (std::size_t c = 0; c < setup.channels.size(); ++c) {
        const plant::Drive& d = setup.channels[c].drive;
        if (d.kind == plant::Drive::Kind::None) continue;
        const std::string ch = "plant channel " + std::to_string(c);
        t.push_back({{d.device.area, d.device.index, 1},
                     d.kind == plant::Drive::Kind::Output
                         ? "heater output of " + ch + " (its duty is the power)"
                         : "drives " + ch + ", full power at " +
                               std::to_string(static_cast<long>(d.full_scale))});
    }
    return t;
}

/// The first fixed row of `map` that serves the device (the order WireMap and --print-map
/// use), as a table and address; packed rows serve words of bits, not bits.
bool locate(const modbus::AddressMap& map,
            Area area,
            std::uint32_t index,
            Table& table,
            std::uint16_t& address) {
    for (const auto& r : map.rows()) {
        if (r.packed || r.devices.area != area || index < r.devices.start ||
            index >= r.devices.end())
            continue;
        table = r.table;
        address = static_cast<std::uint16_t>(r.wire_start + (index - r.devices.start));
        return true;
    }
    return false;
}

bool bit_table(Table t) { return t == Table::Coils || t == Table::DiscreteInputs; }

/// True when the unit serves `index` of `area` at `address` (a family's maps held in the image,
/// which a preset may switch on, move addresses).
bool served(Plc& plc,
            Table table,
            std::uint16_t address,
            std::uint16_t n,
            Area area,
            std::uint32_t index,
            bool write) {
    const modbus::Window w = plc.unit().resolve(table, address, n, write);
    if (w.status != modbus::Status::Ok || w.packed || w.count != 0) return false;
    if (bit_table(table)) return w.bits == plc.image().bits(area) + index;
    return w.words == plc.image().words(area) + index;
}

void simulator_rows(const config::Config& config, std::vector<TagRow>& rows) {
    if (config.simulator.unit == 0) return;
    const bool writable = config.simulator.writable.value_or(!config.modbus.read_only);
    for (const auto& r : simulator::register_tags()) {
        rows.push_back({"", "", r.name, "", config.simulator.unit, Table::HoldingRegisters, r.wire,
                        r.is_signed ? "int16" : "uint16",
                        writable && simulator::SimulatorUnit::writable(r.wire), r.description, ""});
    }
}

}  // namespace

std::string csv_field(const std::string& s, bool always) {
    if (!always && s.find_first_of(",\"\n\r") == std::string::npos) return s;
    std::string q = "\"";
    for (char c : s) {
        if (c == '"') q += '"';
        q += c;
    }
    return q + '"';
}

// A byte that is not UTF-8 (a file name's, say) becomes U+FFFD, as JSON text must be Unicode
// (RFC 8259 §8.1); docs/configuration.md says so.
std::string json_string(const std::string& s) {
    std::string q = "\"";
    for (std::size_t i = 0; i < s.size();) {
        const char c = s[i];
        const image::Utf8Char u = image::utf8_char(std::string_view(s).substr(i));
        if (u.length == 0) {
            q += "\\ufffd";
            ++i;
            continue;
        }
        if (c == '"' || c == '\\') {
            q += '\\';
            q += c;
        } else if (static_cast<unsigned char>(c) < 0x20) {
            char buf[8];
            std::snprintf(buf, sizeof buf, "\\u%04x", static_cast<unsigned>(c));
            q += buf;
        } else {
            q.append(s, i, u.length);
        }
        i += u.length;
    }
    return q + '"';
}

const char* table_key(Table table) {
    switch (table) {
        case Table::Coils:
            return "coil";
        case Table::DiscreteInputs:
            return "discrete_input";
        case Table::HoldingRegisters:
            return "holding_register";
        case Table::InputRegisters:
            return "input_register";
    }
    return "?";
}

TagExport export_tags(const config::Config& config) {
    const profiles::Profile& profile = profiles::of(config);
    const image::Naming& naming = profile.naming();
    Plc plc(config);  // presets applied: tables the profile reads from the image are in place
    const image::Layout& layout = plc.image().layout();

    engine::Tags operands;
    const engine::Program program = build_program(config, &operands);
    engine::Tags blocks;
    for (const auto& i : program) i->describe(plc.image(), blocks);

    Meanings meanings;
    add(meanings, operands, naming, layout);
    add(meanings, blocks, naming, layout);
    add(meanings, profile.tags(config, plc.image()), naming, layout);
    add(meanings, config_tags(config, program), naming, layout);

    const std::unique_ptr<modbus::AddressMap> own = map_of(config);
    const modbus::AddressMap& map = own ? *own : profile.map();
    const bool fatek = profile.speaks("fatek");
    TagExport out;
    for (const auto& [key, m] : meanings) {
        const auto [area, index] = key;
        const std::string device = naming.format_device(area, index);
        const bool wide =
            area == Area::CV && naming.counter_words(naming.counter_of_word(index)) == 2;
        const auto n = static_cast<std::uint16_t>(wide ? 2 : 1);
        Table table{};
        std::uint16_t address = 0;
        if (!locate(map, area, index, table, address) ||
            !served(plc, table, address, n, area, index, false)) {
            out.unreachable.push_back(device + ": " + joined(m.descriptions));
            continue;
        }
        std::string type = "bool";
        std::string description = joined(m.descriptions);
        if (wide) {
            type = "int32";
            description.insert(0, "32-bit, low word at address, high word at address+1; ");
        } else if (!image::is_bit_area(area)) {
            type = m.is_unsigned ? "uint16" : "int16";
        }
        out.rows.push_back({"", "", device, device, config.station, table, address, type,
                            served(plc, table, address, n, area, index, true), description,
                            fatek ? fatek::device_name(layout, area, index) : std::string()});
    }
    simulator_rows(config, out.rows);
    std::stable_sort(out.rows.begin(), out.rows.end(), [](const TagRow& a, const TagRow& b) {
        // Table's order is the export's: coils, discrete inputs, holding, input registers.
        return std::make_tuple(a.unit, a.table, a.address) <
               std::make_tuple(b.unit, b.table, b.address);
    });
    return out;
}

TagExport export_tags(const std::vector<config::Config>& plcs) {
    TagExport out;
    for (const auto& config : plcs) {
        TagExport e = export_tags(config);
        const std::string id = config::plc_id(config);
        if (!id.empty()) {
            const std::string endpoint = endpoint_of(config);
            for (auto& r : e.rows) {
                r.plc = id;
                r.endpoint = endpoint;
                r.name.insert(0, id + ".");
            }
            for (auto& u : e.unreachable) u.insert(0, id + ".");
        }
        std::move(e.rows.begin(), e.rows.end(), std::back_inserter(out.rows));
        std::move(e.unreachable.begin(), e.unreachable.end(), std::back_inserter(out.unreachable));
    }
    return out;
}

std::string endpoint_of(const config::Config& config) {
    std::string s;
    const config::TcpConfig& tcp = config.modbus.tcp;
    if (tcp.enabled) {
        // An IPv6 address in brackets, as in a URL (RFC 3986 §3.2.2): its colons are not the
        // port's.
        const bool v6 = tcp.bind.find(':') != std::string::npos;
        s = "tcp:" + (v6 ? "[" + tcp.bind + "]" : tcp.bind) + ":" + std::to_string(tcp.port);
    }
    if (config.modbus.rtu) s += (s.empty() ? "rtu:" : " rtu:") + config.modbus.rtu->device;
    return s;
}

void write_tags(std::ostream& out, const std::vector<TagRow>& rows, bool as_json) {
    // The columns: `plc` and `endpoint` only when the rows are of `plcs:` entries, so that a
    // file holding one PLC exports as it always did.
    const bool several =
        std::any_of(rows.begin(), rows.end(), [](const TagRow& r) { return !r.plc.empty(); });
    const bool fatek =
        std::any_of(rows.begin(), rows.end(), [](const TagRow& r) { return !r.fatek.empty(); });
    struct Field {
        const char* key;
        std::string value;
        bool number;
    };
    auto fields = [several, fatek](const TagRow& r) {
        std::vector<Field> f;
        if (several) f.push_back({"plc", r.plc, false});
        f.push_back({"name", r.name, false});
        f.push_back({"device", r.device, false});
        if (fatek) f.push_back({"fatek", r.fatek, false});
        if (several) f.push_back({"endpoint", r.endpoint, false});
        f.push_back({"unit", std::to_string(r.unit), true});
        f.push_back({"table", table_key(r.table), false});
        f.push_back({"address", std::to_string(r.address), true});
        f.push_back({"address_1based", std::to_string(r.address + 1), true});
        f.push_back({"type", r.type, false});
        f.push_back({"access", r.writable ? "read-write" : "read", false});
        f.push_back({"description", r.description, false});
        return f;
    };
    if (!as_json) {
        const auto header = fields(TagRow{});
        for (std::size_t k = 0; k < header.size(); ++k) out << (k ? "," : "") << header[k].key;
        out << '\n';
        for (const auto& r : rows) {
            const auto f = fields(r);
            for (std::size_t k = 0; k < f.size(); ++k)
                out << (k ? "," : "") << (f[k].number ? f[k].value : csv_field(f[k].value));
            out << '\n';
        }
        return;
    }
    out << "[";
    for (std::size_t i = 0; i < rows.size(); ++i) {
        const auto f = fields(rows[i]);
        out << (i ? ",\n" : "\n") << "  {";
        for (std::size_t k = 0; k < f.size(); ++k) {
            out << (k ? ", " : "") << '"' << f[k].key
                << "\": " << (f[k].number ? f[k].value : json_string(f[k].value));
        }
        out << "}";
    }
    out << (rows.empty() ? "]\n" : "\n]\n");
}

bool parse_tag_format(const std::string& name, TagFormat& format) {
    static const std::pair<const char*, TagFormat> kNames[] = {
        {"csv", TagFormat::Csv},         {"json", TagFormat::Json},
        {"kepware", TagFormat::Kepware}, {"ignition", TagFormat::Ignition},
        {"weintek", TagFormat::Weintek},
    };
    for (const auto& [n, f] : kNames) {
        if (name != n) continue;
        format = f;
        return true;
    }
    return false;
}

void write_tags(std::ostream& out, const std::vector<TagRow>& rows, TagFormat format) {
    switch (format) {
        case TagFormat::Csv:
        case TagFormat::Json:
            write_tags(out, rows, format == TagFormat::Json);
            return;
        case TagFormat::Kepware:
            write_kepware(out, rows);
            return;
        case TagFormat::Ignition:
            write_ignition(out, rows);
            return;
        case TagFormat::Weintek:
            write_weintek(out, rows);
            return;
    }
}

}  // namespace plcemu::daemon
