#include "plcemu/config/config.hpp"

#include <arpa/inet.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <functional>
#include <map>
#include <set>
#include <string_view>
#include <tuple>

#include "config/comm_fault_section.hpp"
#include "config/config_file.hpp"
#include "config/fingerprint.hpp"
#include "config/listener_sections.hpp"
#include "config/yaml_tree.hpp"
#include "plcemu/config/family.hpp"
#include "plcemu/config/listener_key.hpp"
#include "plcemu/config/listeners.hpp"
#include "plcemu/config/tree.hpp"
#include "plcemu/image/layout.hpp"
#include "plcemu/image/naming.hpp"
#include "plcemu/image/state_file.hpp"

namespace plcemu::config {

namespace {

// The sections every profile has; a profile adds its own (Family::sections).
constexpr std::array<std::string_view, 15> kCommonSections{
    "profile", "model",   "station", "scan_ms", "time_scale", "modbus",      "fatek", "http",
    "init",    "program", "plant",   "faults",  "simulator",  "persistence", "log"};

// "duplicate device 'D07' (first at line 3 as 'D7')" for a key naming what an earlier key
// (`first`: its text and line) already named.
std::string again(const std::string& kind,
                  const std::string& key,
                  const std::pair<std::string, int>& first) {
    return "duplicate " + kind + " '" + excerpt(key) + "' (first at line " +
           std::to_string(first.second) +
           (first.first == key ? "" : " as '" + excerpt(first.first) + "'") + ")";
}

}  // namespace

void read_rtu(const Reader& r, const Node& n, RtuConfig& rtu, const std::string& what, bool slave) {
    read_line(r, n, rtu, what, false, slave);
    // An RTU frame is binary: every byte 8 bits (Modbus over Serial Line, 2.5.1). Seven are
    // FATEK's (and Modbus ASCII's), which a master on this line would not speak.
    r.attempt([&] {
        if (n["data_bits"] && rtu.data_bits != 8) {
            r.fail(n["data_bits"], what + ".data_bits: Modbus RTU carries 8-bit bytes: expected 8");
        }
    });
}

void read_line(const Reader& r,
               const Node& n,
               RtuConfig& rtu,
               const std::string& what,
               bool with_read_only,
               bool slave) {
    std::vector<std::string> keys{"device", "baud", "parity", "data_bits", "stop_bits"};
    if (with_read_only) keys.emplace_back("read_only");
    if (slave) keys.emplace_back("echo");
    r.check_keys(n, what, keys);
    r.attempt([&] {
        if (slave && n["echo"]) rtu.echo = r.boolean(n["echo"], what + ".echo");
    });
    r.attempt([&] {
        if (with_read_only && n["read_only"])
            rtu.read_only = r.boolean(n["read_only"], what + ".read_only");
    });
    r.attempt([&] {
        if (!n["device"]) r.fail(n, what + ": 'device' is required");
        rtu.device = r.scalar(n["device"], what + ".device");
    });
    r.attempt([&] {
        if (!n["baud"]) return;
        const long long b = r.integer(n["baud"], what + ".baud", 300, 921600);
        static const std::set<long long> kBauds{300,   600,   1200,   2400,   4800,   9600,  19200,
                                                38400, 57600, 115200, 230400, 460800, 921600};
        if (!kBauds.count(b)) r.fail(n["baud"], what + ".baud: not a standard baud rate");
        rtu.baud = static_cast<int>(b);
    });
    r.attempt([&] {
        if (!n["parity"]) return;
        const std::string p = r.scalar(n["parity"], what + ".parity");
        if (p != "N" && p != "E" && p != "O")
            r.fail(n["parity"], what + ".parity: expected N, E or O");
        rtu.parity = p[0];
    });
    r.attempt([&] {
        if (n["data_bits"])
            rtu.data_bits = static_cast<int>(r.integer(n["data_bits"], what + ".data_bits", 7, 8));
    });
    r.attempt([&] {
        if (n["stop_bits"])
            rtu.stop_bits = static_cast<int>(r.integer(n["stop_bits"], what + ".stop_bits", 1, 2));
    });
}

std::string outside(const image::Naming& naming,
                    const image::Layout& layout,
                    const image::Range& rg) {
    const std::string area(naming.area_name(rg.area));
    const std::string name = naming.format_range(rg);
    if (layout.size_of(rg.area) == 0) {
        return name + " does not exist on this PLC (it has no " + area + " area)";
    }
    if (rg.count <= layout.size_of(rg.area) && rg.start <= layout.size_of(rg.area) - rg.count) {
        return name + " does not exist on this PLC (no " + area + " device has that number)";
    }
    // Devices, not entries: 256 counters whose values fill 312 words.
    return name + " is outside this PLC's " + area + " area (" +
           std::to_string(naming.devices_in({rg.area, 0, layout.size_of(rg.area)})) + " devices)";
}

namespace {

std::string outside(const Reader& r, const image::Layout& layout, const image::Range& rg) {
    return config::outside(r.naming(), layout, rg);
}

// Device ranges of a list (write_protect, retentive) must exist on the profile's PLC. An entry
// that is no range was refused where the list was read, and is not refused twice.
void check_ranges_exist(const Reader& r,
                        const Node& list,
                        const std::string& what,
                        const image::Layout& layout) {
    if (!list || !list.is_sequence()) return;
    for (const auto& e : list.items) {
        const auto rg = e.is_scalar() ? r.naming().parse_range(e.text) : std::nullopt;
        if (rg && !layout.contains(*rg)) r.report(e, what + ": " + outside(r, layout, *rg));
    }
}

// One row of `modbus.map`, checked against the rows before it.
void read_map_row(const Reader& r,
                  const Node& e,
                  const image::Layout& layout,
                  std::vector<MapRowConfig>& rows) {
    r.check_keys(e, "modbus.map row", {"table", "start", "device", "count", "access"});
    for (const char* k : {"table", "start", "device", "count"}) {
        if (!e[k]) r.fail(e, std::string("modbus.map row: '") + k + "' is required");
    }
    MapRowConfig row;
    row.pos = r.pos(e);
    const std::string t = r.scalar(e["table"], "modbus.map.table");
    if (t == "coils") {
        row.table = MapTable::Coils;
    } else if (t == "discrete_inputs") {
        row.table = MapTable::DiscreteInputs;
    } else if (t == "holding") {
        row.table = MapTable::Holding;
    } else if (t == "input") {
        row.table = MapTable::Input;
    } else {
        r.fail(e["table"],
               "modbus.map.table: expected coils, discrete_inputs, holding or "
               "input, got '" +
                   excerpt(t) + "'");
    }
    row.start = static_cast<std::uint16_t>(r.integer(e["start"], "modbus.map.start", 0, 65535));
    row.count = static_cast<std::uint16_t>(r.integer(e["count"], "modbus.map.count", 1, 65535));
    if (std::uint32_t{row.start} + row.count > 65536) {
        r.fail(e["count"], "modbus.map.count: the row runs past wire address 65535");
    }
    row.text = r.scalar(e["device"], "modbus.map.device");
    row.device = r.device(e["device"], "modbus.map.device");
    const bool bit_table = row.table == MapTable::Coils || row.table == MapTable::DiscreteInputs;
    const bool bit_device = image::is_bit_area(row.device.area);
    if (bit_table && (!bit_device || row.device.word_of_bits)) {
        r.fail(e["device"], "modbus.map.device: a " + t + " row needs a bit device, got '" +
                                excerpt(row.text) + "'");
    }
    if (!bit_table && bit_device && !row.device.word_of_bits) {
        r.fail(e["device"],
               "modbus.map.device: a register table needs a word device or 16 "
               "packed bits such as WM0, got '" +
                   excerpt(row.text) + "'");
    }
    const std::uint32_t per = row.device.word_of_bits ? 16 : 1;
    const image::Range devices{row.device.area, row.device.index, per * row.count};
    if (!layout.contains(devices)) r.fail(e, "modbus.map row: " + outside(r, layout, devices));
    if (const auto& a = e["access"]) {
        const std::string s = r.scalar(a, "modbus.map.access");
        if (s != "ro" && s != "rw") r.fail(a, "modbus.map.access: expected ro or rw");
        row.read_only = s == "ro";
    }
    for (const auto& o : rows) {
        if (o.table == row.table && row.start < o.start + o.count &&
            o.start < row.start + row.count) {
            r.fail(e, "modbus.map row: wire addresses " + std::to_string(row.start) + "-" +
                          std::to_string(row.start + row.count - 1) + " overlap the row at line " +
                          std::to_string(o.pos.line));
        }
    }
    rows.push_back(std::move(row));
}

// `modbus.map`: rows of a map that replaces the profile's.
void read_map(const Reader& r,
              const Node& n,
              const image::Layout& layout,
              std::vector<MapRowConfig>& rows) {
    if (!n.is_sequence())
        r.fail(n,
               "modbus.map: expected a list of rows such as {table: holding, start: 0, device: D0, "
               "count: 100}");
    for (const auto& e : n.items) r.attempt([&] { read_map_row(r, e, layout, rows); });
}

void read_modbus(const Reader& r, const Node& n, ModbusConfig& mb) {
    r.check_keys(n, "modbus", {"tcp", "rtu", "read_only", "write_protect", "map"});
    r.attempt([&] {
        if (n["tcp"]) read_tcp(r, n["tcp"], mb.tcp, "modbus.tcp");
    });
    r.attempt([&] {
        if (n["rtu"] && !n["rtu"].is_null()) {
            RtuConfig rtu;
            read_rtu(r, n["rtu"], rtu, "modbus.rtu", true);
            mb.rtu = rtu;
        }
    });
    r.attempt([&] {
        if (n["read_only"]) mb.read_only = r.boolean(n["read_only"], "modbus.read_only");
    });
    r.attempt([&] {
        if (const auto& w = n["write_protect"]) {
            if (!w.is_sequence())
                r.fail(w, "modbus.write_protect: expected a list of device ranges");
            for (const auto& e : w.items) {
                r.attempt(
                    [&] { mb.write_protect.push_back(r.range(e, "modbus.write_protect entry")); });
            }
        }
    });
}

// Each device must exist on the profile's PLC, every value of a list included: checked here, at
// its key, so that each is refused on its own (the build refused the first only, and only in a
// file with no other error).
void read_init(const Reader& r,
               const Node& n,
               std::vector<InitEntry>& init,
               const image::Layout& layout) {
    r.expect_map(n, "init");
    // Keys naming one device (D7, d7, D07) would preset it twice, the last silently winning.
    std::map<std::tuple<image::Area, std::uint32_t, bool>, std::pair<std::string, int>> first;
    for (const auto& entry : n.entries) {
        r.attempt([&] {
            const auto* it = &entry;
            InitEntry e;
            e.pos = r.pos(it->first);
            e.device = r.device(it->first, "init key");
            const std::string key = it->first.text;
            const auto [at, fresh] = first.try_emplace(
                {e.device.area, e.device.index, e.device.word_of_bits}, key, e.pos.line);
            if (!fresh) r.fail(it->first, "init: " + again("device", key, at->second));
            const std::string what = "init." + excerpt(key);
            // A bit device takes 0 or 1 (2 or -1 once read as ON without a word); a word, or 16
            // bits of a WMn, any 16-bit value.
            const bool bit = image::is_bit_area(e.device.area) && !e.device.word_of_bits;
            auto one = [&](const Node& v) {
                e.values.push_back(static_cast<std::uint16_t>(
                    r.integer(v, what, bit ? 0 : -32768, bit ? 1 : 65535) & 0xFFFF));
            };
            const Node& value = it->second;
            if (value.is_sequence()) {
                for (const auto& v : value.items) one(v);
            } else {
                one(value);
            }
            if (!layout.contains(e.range())) {
                r.fail(it->first, "init: " + outside(r, layout, e.range()));
            }
            init.push_back(std::move(e));
        });
    }
}

// The most lines a program file may have (docs/program-language.md).
constexpr int kMaxListingLines = 400'000;

// The lines of a program file: each with its file, line and column 1.
void read_listing_file(const Reader& r, const Node& file, std::vector<ListingLineConfig>& listing) {
    const std::string name = r.scalar(file, "program.file");
    if (name.empty()) r.fail(file, "program.file: expected a file name");
    // Relative to the directory of the config file that names it, as a state file is.
    const std::filesystem::path target(name);
    const std::filesystem::path base = std::filesystem::path(file.pos.file.str()).parent_path();
    const std::string path = target.is_absolute() || base.empty() ? name : (base / target).string();
    std::string text;
    try {
        text = read_config_file(path, "the program file " + path);
    } catch (const ConfigError& e) {
        r.fail(file, "program.file: " + e.message());
    }
    // A UTF-8 byte order mark, as editors on Windows save a text file, is not part of the first
    // statement (the YAML reader skips it as well).
    std::size_t start = text.starts_with("\xEF\xBB\xBF") ? 3 : 0;
    int line = 1;
    while (start <= text.size()) {
        // A line ends in LF, CR LF or a lone CR (as classic Mac OS editors save one): read as
        // one line, a file of the last kind was a single statement, or a comment.
        std::size_t end = text.find_first_of("\r\n", start);
        if (end == std::string::npos) end = text.size();
        const std::size_t next = text.compare(end, 2, "\r\n") == 0 ? end + 2 : end + 1;
        if (end > start || end < text.size()) {
            // Room for the most statements a program holds, with comments and operand lines.
            // Refused at the line that crosses the limit, as a statement past 100,000 is.
            if (line > kMaxListingLines) {
                throw ConfigError(Position{path, line, 1}, "program.file: more than " +
                                                               std::to_string(kMaxListingLines) +
                                                               " lines; refused");
            }
            listing.push_back({text.substr(start, end - start), {path, line, 1}});
        }
        if (end == text.size()) break;
        start = next;
        ++line;
    }
}

// `program: {file: oven.il}` or `program: {il: ["LD X0", "OUT Y0"]}`.
void read_listing(const Reader& r, const Node& n, std::vector<ListingLineConfig>& listing) {
    r.check_keys(n, "program", {"file", "il"});
    if (static_cast<bool>(n["file"]) == static_cast<bool>(n["il"])) {
        r.fail(n, "program: expected either 'file' (an instruction-list file) or 'il' (its lines)");
    }
    if (const auto& f = n["file"]) return read_listing_file(r, f, listing);
    const auto& il = n["il"];
    if (!il.is_sequence()) {
        r.fail(il,
               "program.il: expected a list of lines, one statement each, such as "
               "['LD X0', 'OUT Y0'] (or a file: program: {file: oven.il})");
    }
    for (const auto& line : il.items) {
        Position at = r.pos(line);
        if (line.quoted) ++at.column;  // the statement starts after the quote
        listing.push_back({r.scalar(line, "program.il line"), at});
    }
}

void read_program(const Reader& r,
                  const Node& n,
                  std::vector<InstructionConfig>& prog,
                  std::vector<ListingLineConfig>& listing) {
    if (n.is_null()) return;
    if (n.is_map()) return read_listing(r, n, listing);
    if (!n.is_sequence()) {
        r.fail(n,
               "program: expected a list of instructions, or an instruction list "
               "({file: oven.il} or {il: [...]})");
    }
    for (const auto& item : n.items) {
        r.attempt([&] {
            if (!item.is_map() || item.size() != 1) {
                r.fail(item,
                       "program entry: expected one instruction with its operands, such as "
                       "'MOV: {en: M0, s: K5, d: D0}'");
            }
            const auto& kv = item.entries.front();
            InstructionConfig ic;
            ic.mnemonic = r.scalar(kv.first, "instruction");
            ic.pos = r.pos(kv.first);
            const std::string mnemonic = excerpt(ic.mnemonic);
            if (!kv.second.is_map())
                r.fail(kv.second, mnemonic + ": expected a mapping of operands");
            for (const auto& entry : kv.second.entries) {
                const auto* op = &entry;
                const std::string key = r.scalar(op->first, mnemonic + " operand");
                for (const auto& [k, v] : ic.operands) {
                    if (k == key) {
                        r.fail(op->first, mnemonic + ": duplicate operand '" + excerpt(key) + "'");
                    }
                }
                ic.operands.emplace_back(
                    key, Operand{r.scalar(op->second, mnemonic + "." + excerpt(key)),
                                 r.pos(op->second)});
            }
            prog.push_back(std::move(ic));
        });
    }
}

void read_faults(const Reader& r, const Node& n, Faults& f) {
    r.check_keys(n, "faults", {"sensor_broken", "heater_open", "heater_shorted", "reading_frozen"});
    r.attempt([&] {
        if (n["sensor_broken"])
            f.sensor_broken = r.boolean(n["sensor_broken"], "faults.sensor_broken");
    });
    r.attempt([&] {
        if (n["heater_open"]) f.heater_open = r.boolean(n["heater_open"], "faults.heater_open");
    });
    r.attempt([&] {
        if (n["heater_shorted"])
            f.heater_shorted = r.boolean(n["heater_shorted"], "faults.heater_shorted");
    });
    r.attempt([&] {
        if (n["reading_frozen"])
            f.reading_frozen = r.boolean(n["reading_frozen"], "faults.reading_frozen");
    });
}

void read_channel(const Reader& r, const Node& n, ChannelConfig& c, const std::string& what) {
    r.check_keys(n, what,
                 {"ambient", "k", "tau", "dead_time", "noise", "cooling", "lead_resistance",
                  "drive", "drive_full_scale", "faults"});
    r.attempt([&] {
        if (n["ambient"])
            c.params.ambient_c = r.number(n["ambient"], what + ".ambient", -200, 1000);
    });
    r.attempt([&] {
        if (n["k"]) c.params.k_c = r.number(n["k"], what + ".k", 0, 3000);
    });
    r.attempt([&] {
        if (n["tau"]) c.params.tau_s = r.number(n["tau"], what + ".tau", 0.1, 100000);
    });
    r.attempt([&] {
        if (n["dead_time"])
            c.params.dead_time_s = r.number(n["dead_time"], what + ".dead_time", 0, 3600);
    });
    r.attempt([&] {
        if (n["noise"]) c.params.noise_c = r.number(n["noise"], what + ".noise", 0, 100);
    });
    r.attempt([&] {
        if (n["cooling"]) c.params.cooling = r.boolean(n["cooling"], what + ".cooling");
    });
    r.attempt([&] {
        if (n["lead_resistance"]) {
            c.params.lead_ohm = r.number(n["lead_resistance"], what + ".lead_resistance", 0, 100);
        }
    });
    r.attempt([&] {
        if (n["drive"]) {
            c.drive = r.device(n["drive"], what + ".drive");
            const auto a = c.drive->area;
            if (c.drive->word_of_bits ||
                (a != image::Area::Y && a != image::Area::R && a != image::Area::D)) {
                r.fail(n["drive"], what + ".drive: expected a Y output (PWM) or a register");
            }
        }
    });
    r.attempt([&] {
        if (n["drive_full_scale"]) {
            c.drive_full_scale = static_cast<int>(
                r.integer(n["drive_full_scale"], what + ".drive_full_scale", 1, 32767));
        }
    });
    r.attempt([&] {
        if (n["faults"]) read_faults(r, n["faults"], c.faults);
    });
}

void read_plant(const Reader& r, const Node& n, PlantConfig& p) {
    r.check_keys(n, "plant", {"defaults", "channels", "seed"});
    r.attempt([&] {
        if (n["defaults"]) read_channel(r, n["defaults"], p.defaults, "plant.defaults");
    });
    r.attempt([&] {
        if (n["seed"])
            p.seed = static_cast<std::uint64_t>(r.integer(n["seed"], "plant.seed", 0, 1LL << 40));
    });
    if (const auto& ch = n["channels"]) {
        r.expect_map(ch, "plant.channels");
        // Keys naming one channel (1, 01, 0x1) would set it twice, the last silently winning.
        std::map<int, std::pair<std::string, int>> first;
        for (const auto& entry : ch.entries) {
            r.attempt([&] {
                const auto* it = &entry;
                const int idx = static_cast<int>(r.integer(it->first, "plant.channels key", 0, 31));
                const std::string key = it->first.text;
                const auto [at, fresh] = first.try_emplace(idx, key, r.pos(it->first).line);
                if (!fresh)
                    r.fail(it->first, "plant.channels: " + again("channel", key, at->second));
                ChannelConfig c = p.defaults;
                read_channel(r, it->second, c, "plant.channels." + std::to_string(idx));
                p.channels.emplace_back(idx, c);
            });
        }
    }
}

void read_persistence(const Reader& r, const Node& n, PersistenceConfig& p) {
    r.check_keys(n, "persistence", {"enabled", "file", "retentive", "sync_ms", "init"});
    r.attempt([&] {
        if (n["enabled"]) p.enabled = r.boolean(n["enabled"], "persistence.enabled");
    });
    r.attempt([&] {
        if (n["file"]) p.file = r.scalar(n["file"], "persistence.file");
    });
    r.attempt([&] {
        if (n["init"]) {
            const std::string s = r.scalar(n["init"], "persistence.init");
            if (s != "fresh" && s != "always") {
                r.fail(n["init"],
                       "persistence.init: expected 'fresh' (presets only on a new state "
                       "file) or 'always'");
            }
            p.init = s == "always" ? InitPolicy::Always : InitPolicy::Fresh;
        }
    });
    r.attempt([&] {
        if (n["sync_ms"])
            p.sync_ms =
                static_cast<int>(r.integer(n["sync_ms"], "persistence.sync_ms", 10, 600000));
    });
    r.attempt([&] {
        if (const auto& ret = n["retentive"]) {
            if (!ret.is_sequence())
                r.fail(ret, "persistence.retentive: expected a list of device ranges");
            std::vector<image::Range> v;
            for (const auto& e : ret.items) {
                r.attempt([&] { v.push_back(r.range(e, "persistence.retentive entry")); });
            }
            // The state file's header records them, with those the family always keeps.
            if (v.size() > image::kMaxConfiguredRanges) {
                std::string why = "persistence.retentive: at most ";
                why += std::to_string(image::kMaxConfiguredRanges);
                r.fail(ret, why + " ranges");
            }
            p.retentive = v;
        }
    });
}

void read_log(const Reader& r, const Node& l, LogConfig& log) {
    r.check_keys(l, "log", {"level"});
    r.attempt([&] {
        if (l["level"]) {
            log.level = r.scalar(l["level"], "log.level");
            static const std::set<std::string> kLevels{"trace", "debug", "info",
                                                       "warn",  "error", "off"};
            if (!kLevels.count(log.level))
                r.fail(l["level"], "log.level: expected trace, debug, info, warn, error or off");
        }
    });
}

void read_simulator(const Reader& r, const Node& s, SimulatorConfig& sim) {
    r.check_keys(s, "simulator", {"unit", "writable"});
    r.attempt([&] {
        if (!s["unit"]) return;
        sim.unit = static_cast<int>(r.integer(s["unit"], "simulator.unit", 0, 255));
        if (sim.unit == 255) {
            r.fail(s["unit"],
                   "simulator.unit: 255 is \"the device itself\" over Modbus TCP (the PLC "
                   "answers it alone on its listener, nobody behind a shared one), so the "
                   "simulator could never be reached; use 1-254, or 0 for none");
        }
    });
    r.attempt([&] {
        if (s["writable"]) sim.writable = r.boolean(s["writable"], "simulator.writable");
    });
}

// Reads the section `key` of `root` with `read` when it is there; an error in it is recorded and
// the other sections are still read.
template <class Value>
void section(const Reader& r,
             const Node& root,
             const char* key,
             void (*read)(const Reader&, const Node&, Value&),
             Value& out) {
    r.attempt([&] {
        if (const Node& n = root[key]) read(r, n, out);
    });
}

// "profiles fb and fbs do", "no profile does".
std::string speakers(std::string_view protocol) {
    std::vector<std::string> names;
    for (const Family* f : families()) {
        if (f->speaks(protocol)) names.emplace_back(f->name());
    }
    if (names.empty()) return "no profile does";
    std::string s = names.size() == 1 ? "profile " : "profiles ";
    for (std::size_t i = 0; i < names.size(); ++i) {
        if (i > 0) s += i + 1 == names.size() ? " and " : ", ";
        s += names[i];
    }
    return s + (names.size() == 1 ? " does" : " do");
}

void check_own_listeners(const Reader& r,
                         const Node& entry,
                         const Config& c,
                         const Overrides& overrides);

// A PLC's station and its simulator unit are two unit IDs on its listeners: the same one would
// leave the simulator unreachable (docs/configuration.md, "Configuration").
void check_own_units(const Reader& r, const Node& root, const Config& c) {
    if (c.simulator.unit == 0 || c.simulator.unit != c.station) return;
    const std::string n = std::to_string(c.station);
    if (const Node& unit = root["simulator"]["unit"]) {
        r.fail(unit, "simulator.unit: " + n +
                         " is also this PLC's station, so the simulator could never be reached "
                         "(give it another unit, or 0 for none)");
    }
    r.fail(root["station"], "station: " + n +
                                " is also this PLC's simulator unit (simulator.unit defaults to "
                                "247), which could then never be reached: choose another "
                                "station, or set simulator.unit (0 for none)");
}

// `entry`: a `plcs:` entry, which may have a `name:` and may not have `log:` (one process, one
// log).
Config read_root(Reader& r, const Node& root, const Overrides& overrides, bool entry = false) {
    Config c;
    const std::size_t errors_before = r.errors_found();
    if (!root.is_map()) {
        r.fail(root, "the config must be a mapping with at least 'profile:' (one of " +
                         family_names() + ")");
    }
    // The common sections, and those a profile reads itself (which may not be this one's). The
    // profiles registered themselves before main(): the list is made once.
    static const std::vector<std::string> known = [] {
        std::vector<std::string> k(kCommonSections.begin(), kCommonSections.end());
        for (const Family* p : families()) {
            for (std::string_view s : p->sections()) {
                if (std::find(k.begin(), k.end(), s) == k.end()) k.emplace_back(s);
            }
        }
        return k;
    }();
    if (entry) {
        if (root["log"]) {
            r.report(root["log"], "log: applies to the whole process; put it beside 'plcs:'");
        }
        static const std::vector<std::string> known_in_entry = [] {
            std::vector<std::string> k = known;
            k.emplace_back("name");
            return k;
        }();
        r.check_keys(root, "plcs entry", known_in_entry);
    } else {
        r.check_keys(root, "config", known);
    }
    if (!root["profile"]) r.fail(root, "'profile' is required (one of " + family_names() + ")");
    c.profile = r.scalar(root["profile"], "profile");
    const Family* profile = find_family(c.profile);
    if (profile == nullptr) {
        r.fail(root["profile"],
               "profile: expected one of " + family_names() + ", got '" + excerpt(c.profile) + "'");
    }
    r.set_naming(profile->naming());
    const image::Layout layout = profile->layout();
    // A profile's own sections are kept as written for it to read; another profile's are
    // refused where they stand (an unknown key was refused above).
    const auto own = profile->sections();
    for (const auto& [key, value] : root.entries) {
        if (!key.is_scalar() || (entry && key.text == "name")) continue;
        if (std::find(kCommonSections.begin(), kCommonSections.end(), key.text) !=
                kCommonSections.end() ||
            std::find(known.begin(), known.end(), key.text) == known.end()) {
            continue;
        }
        if (std::find(own.begin(), own.end(), key.text) == own.end()) {
            r.report(value, key.text + ": profile " + c.profile + " has no such subsystem");
            continue;
        }
        c.sections.emplace_back(key.text, value);
    }
    // Each key on its own: one in error is recorded and the others are still read.
    c.model = std::string(profile->default_model());
    r.attempt([&] {
        if (!root["model"]) return;
        c.model = r.scalar(root["model"], "model");
        if (!profile->valid_model(c.model))
            r.fail(root["model"], "model: expected " + std::string(profile->model_hint()) +
                                      ", got '" + excerpt(c.model) + "'");
    });
    r.attempt([&] {
        if (root["station"]) {
            c.station = static_cast<std::uint8_t>(
                r.integer(root["station"], "station", 1, profile->max_station()));
        }
    });
    r.attempt([&] {
        if (root["scan_ms"])
            c.scan_ms = static_cast<int>(r.integer(root["scan_ms"], "scan_ms", 1, 1000));
    });
    r.attempt([&] {
        if (root["time_scale"])
            c.time_scale = r.number(root["time_scale"], "time_scale", 0.001, 100000);
    });
    section(r, root, "modbus", read_modbus, c.modbus);
    r.attempt([&] {
        const Node& f = root["fatek"];
        if (!f) return;
        if (!profile->speaks("fatek")) {
            // At the key: the section as a whole is refused.
            const Node* at = &f;
            for (const auto& [key, value] : root.entries) {
                if (key.is_scalar() && key.text == "fatek") at = &key;
            }
            r.fail(*at, "fatek: profile " + c.profile + " does not speak FATEK's protocol (" +
                            speakers("fatek") + ")");
        }
        read_fatek(r, f, c.fatek);
    });
    r.attempt([&] { read_http(r, root["http"], c.http, overrides.http_port.has_value()); });
    r.attempt([&] {
        if (const Node& n = root["init"]) read_init(r, n, c.init, layout);
    });
    r.attempt([&] {
        if (const Node& n = root["program"]) read_program(r, n, c.program, c.listing);
    });
    section(r, root, "plant", read_plant, c.plant);
    section(r, root, "faults", read_comm_faults, c.faults);
    if (c.faults.devices && !layout.contains(*c.faults.devices)) {
        r.report(root["faults"]["from"], "faults.from: " + outside(r, layout, *c.faults.devices));
    }
    section(r, root, "simulator", read_simulator, c.simulator);
    section(r, root, "persistence", read_persistence, c.persistence);
    r.attempt([&] {
        const auto& m = root["modbus"];
        if (!m.is_map()) return;
        check_ranges_exist(r, m["write_protect"], "modbus.write_protect entry", layout);
        if (m["map"]) {
            c.modbus.map.emplace();
            read_map(r, m["map"], layout, *c.modbus.map);
        }
    });
    if (const auto& p = root["persistence"]; p.is_map()) {
        check_ranges_exist(r, p["retentive"], "persistence.retentive entry", layout);
    }
    if (!entry) section(r, root, "log", read_log, c.log);  // an entry's was refused above
    // The checks below compare what several keys said: after an error in one of them they would
    // only repeat it in other words (docs/configuration.md, "Configuration").
    if (r.errors_found() != errors_before) return c;
    apply(overrides, c);
    check_own_units(r, root, c);
    c.settings = profile->read(c, r);
    check_own_listeners(r, root, c, overrides);
    return c;
}

// An entry's name goes into its state file's name and into log lines.
bool valid_entry_name(const std::string& s) {
    return !s.empty() && s.size() <= 32 &&
           s.find_first_not_of(
               "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789_-") ==
               std::string::npos;
}

// The node of `key` under `at`, or the nearest ancestor written: where an error points.
const Node& where(const Node& entry, std::initializer_list<const char*> path) {
    const Node* n = &entry;
    for (const char* k : path) {
        const Node& next = (*n)[k];
        if (!next) return *n;
        n = &next;
    }
    return *n;
}

// The node of `key` in a dotted `section` ("fatek.tcp") under `entry`, or the nearest ancestor
// written.
const Node& where_in(const Node& entry, std::string_view section, const char* key) {
    const Node* n = &entry;
    std::string_view rest = section;
    while (!rest.empty()) {
        const auto dot = rest.find('.');
        const std::string part(rest.substr(0, dot));
        rest = dot == std::string_view::npos ? std::string_view() : rest.substr(dot + 1);
        const Node& next = (*n)[part.c_str()];
        if (!next) return *n;
        n = &next;
    }
    const Node& k = (*n)[key];
    return k ? k : *n;
}

// The protocol of a family's own port (a master's serial line) among an entry's listeners.
constexpr std::string_view kOwnPort = "own port";

// One listener an entry takes, with its key worked out once. Its settings are copied: the
// entry's Config moves on into the list of entries.
struct Held {
    Held(const ListenerConfig& from, std::string k)
        : protocol(from.protocol),
          section(from.section),
          carrier(from.carrier),
          net(from.net != nullptr ? *from.net : TcpConfig{}),
          line(from.line != nullptr ? *from.line : RtuConfig{}),
          key(std::move(k)),
          any(from.net != nullptr && any_address(from.net->bind)) {}

    std::string_view protocol;
    std::string_view section;
    Carrier carrier;
    TcpConfig net;     // Tcp and Udp
    RtuConfig line;    // Serial
    std::string key;   // listener_key
    bool any = false;  // bound to every address
};

// What an entry takes that another may share or clash with, worked out once per entry: the keys
// resolve addresses and device paths, and every later entry is compared with this one.
struct Taken {
    std::vector<Held> listeners;
    std::string state_file;  // state_file_key, empty without persistence
    Position state_at;       // where the entry names it (the entry itself for the default)

    Taken(const Config& c, const Node& entry) {
        for (const ListenerConfig& l : listeners_of(c)) {
            // A port of 0 is the kernel's choice: never shared, never a clash.
            if (l.net != nullptr && l.net->port == 0) continue;
            listeners.emplace_back(l, listener_key(l));
        }
        if (c.settings) {
            for (const auto& own : c.settings->own_lines()) {
                const ListenerConfig l{kOwnPort, Carrier::Serial, own.section, nullptr, own.line};
                listeners.emplace_back(l, listener_key(l));
            }
        }
        if (c.persistence.enabled) {
            // Where the daemon will open it, so --check-config compares what a start would.
            const char* dir = std::getenv("STATE_DIRECTORY");
            state_file = state_file_key(state_file_path(c, dir ? dir : ""));
            state_at = where(entry, {"persistence", "file"}).pos;
        }
    }
};

// Two listeners are one for the kernel: the same serial device, or one port of one carrier where
// either takes every address or both take the same one, however each writes it.
bool same_listener(const Held& a, const Held& b) {
    if (a.carrier != b.carrier) return false;
    if (a.carrier == Carrier::Serial) return a.key == b.key;
    if (a.net.port != b.net.port) return false;
    return a.key == b.key || a.any || b.any;
}

// "tcp listener 0.0.0.0:502", "udp listener ...", "serial line '/dev/ttyS0'".
std::string listener_words(const Held& l) {
    if (l.carrier == Carrier::Serial) return "serial line '" + excerpt(l.line.device) + "'";
    return std::string(l.carrier == Carrier::Tcp ? "tcp" : "udp") + " listener " + l.net.bind +
           ":" + std::to_string(l.net.port);
}

// PLCs on one listener are told apart by unit ID: each needs a station and (Modbus) a simulator
// unit of its own there (docs/configuration.md, "Sharing a listener").
void check_units(const Reader& r,
                 const Node& entry,
                 const Config& c,
                 const Config& o,
                 const std::string& listener,
                 bool simulator) {
    const std::string shared = " on the shared " + listener;
    if (c.station == o.station) {
        r.fail(where(entry, {"station"}), "station: " + std::to_string(c.station) + " is also " +
                                              o.label + "'s" + shared +
                                              " (each PLC there needs a station of its own)");
    }
    if (!simulator) return;
    const int sim = c.simulator.unit;
    const int other_sim = o.simulator.unit;
    if (sim != 0 && (sim == other_sim || sim == o.station)) {
        r.fail(where(entry, {"simulator", "unit"}),
               "simulator.unit: " + std::to_string(sim) + " is also " + o.label + "'s " +
                   (sim == other_sim ? "simulator unit" : "station") + shared +
                   " (give each PLC there a simulator unit of its own, or 0 for none)");
    }
    if (other_sim != 0 && c.station == other_sim) {
        r.fail(where(entry, {"station"}), "station: " + std::to_string(c.station) + " is " +
                                              o.label + "'s simulator unit" + shared);
    }
}

// PLCs behind one TCP or UDP listener share its settings: they must say the same.
void check_net_agrees(
    const Reader& r, const Node& entry, const Held& mine, const Held& theirs, const Config& o) {
    const TcpConfig& a = mine.net;
    const TcpConfig& b = theirs.net;
    const std::string section(mine.section);
    if (mine.key != theirs.key) {
        r.fail(where_in(entry, section, "port"),
               section + ".port: " + std::to_string(a.port) + " is also " + o.label +
                   "'s on another address (PLCs share a port only with the same " + section +
                   ".bind)");
    }
    const char* key = a.unknown_unit != b.unknown_unit           ? "unknown_unit"
                      : a.allow != b.allow                       ? "allow"
                      : a.max_clients != b.max_clients           ? "max_clients"
                      : a.idle_timeout_s != b.idle_timeout_s     ? "idle_timeout_s"
                      : a.frame_timeout_ms != b.frame_timeout_ms ? "frame_timeout_ms"
                      : a.read_only != b.read_only               ? "read_only"
                      : a.token != b.token                       ? "token"
                      : a.hosts != b.hosts                       ? "hosts"
                                                                 : nullptr;
    if (key == nullptr) return;
    const std::string what = section + "." + key;
    r.fail(where_in(entry, section, key),
           what + ": differs from " + o.label + "'s, which shares the " + listener_words(mine) +
               " (PLCs sharing a listener need the same " + what + ")");
}

// PLCs on one serial line share its settings.
void check_line_agrees(
    const Reader& r, const Node& entry, const Held& mine, const Held& theirs, const Config& o) {
    const RtuConfig& a = mine.line;
    const RtuConfig& b = theirs.line;
    const char* key = a.baud != b.baud             ? "baud"
                      : a.parity != b.parity       ? "parity"
                      : a.data_bits != b.data_bits ? "data_bits"
                      : a.stop_bits != b.stop_bits ? "stop_bits"
                      : a.read_only != b.read_only ? "read_only"
                      : a.echo != b.echo           ? "echo"
                                                   : nullptr;
    if (key == nullptr) return;
    const std::string what = std::string(mine.section) + "." + key;
    r.fail(where_in(entry, mine.section, key),
           what + ": differs from " + o.label + "'s, which shares the serial line '" +
               excerpt(a.device) + "' (PLCs on one line need the same " + what + ")");
}

// One port or line carries one protocol: `mine` may not take what `other` (of `whose`: "this
// PLC's", "plcs[0]'s") takes for another. `overrides`, when given, are the command line's: a
// port one of them set is named as set there, the error standing at the file's key.
void check_one_protocol(const Reader& r,
                        const Node& entry,
                        const Held& mine,
                        const Held& other,
                        const std::string& whose,
                        const Overrides* overrides = nullptr) {
    const bool own = mine.protocol == kOwnPort || other.protocol == kOwnPort;
    if (!own && mine.protocol == other.protocol && mine.section == other.section) return;
    if (mine.carrier == Carrier::Serial) {
        r.fail(where_in(entry, mine.section, "device"),
               std::string(mine.section) + ".device: '" + excerpt(mine.line.device) + "' is also " +
                   whose + " " + std::string(other.section) +
                   (own ? " (a master port's serial line is its own)"
                        : " (one serial line carries one protocol)"));
    }
    const auto set_by = [overrides](std::string_view section) -> std::string_view {
        if (overrides == nullptr) return "";
        if (section == "http" && overrides->http_port) return " (--http-port)";
        if (section == "modbus.tcp" && overrides->port) return " (--port)";
        return "";
    };
    std::string why(mine.section);
    why += ".port";
    why += set_by(mine.section);
    why += ": ";
    why += std::to_string(mine.net.port);
    why += " is also ";
    why += whose;
    why += ' ';
    why += other.section;
    why += " port";
    why += set_by(other.section);
    why += " (one port carries one protocol)";
    r.fail(where_in(entry, mine.section, "port"), why);
}

// A PLC's own listeners may not take one port or line twice.
void check_own_listeners(const Reader& r,
                         const Node& entry,
                         const Config& c,
                         const Overrides& overrides) {
    const Taken mine(c, entry);
    for (std::size_t i = 0; i < mine.listeners.size(); ++i) {
        for (std::size_t j = 0; j < i; ++j) {
            if (same_listener(mine.listeners[i], mine.listeners[j])) {
                check_one_protocol(r, entry, mine.listeners[i], mine.listeners[j], "this PLC's",
                                   &overrides);
            }
        }
    }
}

// What a state file brings beside it: its lock, and the temporary it is made through.
constexpr std::array<std::string_view, 2> kStateCompanions = {".new", ".lock"};

// The devices and files an entry takes, checked against the earlier entries: PLCs may share a
// listener (same bind and port, or same device) when it carries one protocol, they agree on its
// settings and answer to different unit IDs; they cannot write one state file.
// Which earlier entries an entry can clash with, found by name, port, line and state file: a
// config of 5,000 PLCs would otherwise compare each entry with every earlier one.
class Clashes {
public:
    void add(std::size_t i, const Config& c, const Taken& t) {
        if (!c.name.empty()) by_name_[c.name].push_back(i);
        for (const Held& h : t.listeners) {
            auto& v = h.carrier == Carrier::Serial
                          ? by_line_[h.key]
                          : by_port_[{static_cast<int>(h.carrier), h.net.port}];
            if (v.empty() || v.back() != i) v.push_back(i);
        }
        if (!t.state_file.empty()) by_file_[t.state_file].push_back(i);
    }

    // The earlier entries sharing a name, a port, a line or a state file with it, in order.
    std::vector<std::size_t> of(const Config& c, const Taken& mine) const {
        std::vector<std::size_t> out;
        const auto take = [&out](const auto& map, const auto& key) {
            if (const auto it = map.find(key); it != map.end())
                out.insert(out.end(), it->second.begin(), it->second.end());
        };
        if (!c.name.empty()) take(by_name_, c.name);
        for (const Held& m : mine.listeners) {
            if (m.carrier == Carrier::Serial) {
                take(by_line_, m.key);
            } else {
                take(by_port_, std::pair<int, int>{static_cast<int>(m.carrier), m.net.port});
            }
        }
        if (!mine.state_file.empty()) {
            take(by_file_, mine.state_file);
            // A file that is another's lock or temporary, or whose own are another's file.
            for (const std::string_view companion : kStateCompanions) {
                take(by_file_, mine.state_file + std::string(companion));
                if (mine.state_file.ends_with(companion)) {
                    take(by_file_,
                         mine.state_file.substr(0, mine.state_file.size() - companion.size()));
                }
            }
        }
        std::sort(out.begin(), out.end());
        out.erase(std::unique(out.begin(), out.end()), out.end());
        return out;
    }

private:
    std::map<std::string, std::vector<std::size_t>> by_name_;
    std::map<std::string, std::vector<std::size_t>> by_line_;
    std::map<std::pair<int, int>, std::vector<std::size_t>> by_port_;
    std::map<std::string, std::vector<std::size_t>> by_file_;
};

void check_shared(const Reader& r,
                  const Node& entry,
                  const Config& c,
                  const Taken& mine,
                  const std::vector<Config>& earlier,
                  const std::vector<Taken>& theirs,
                  const Clashes& clashes) {
    for (const std::size_t i : clashes.of(c, mine)) {
        const Config& o = earlier[i];
        const Taken& t = theirs[i];
        if (!c.name.empty() && c.name == o.name) {
            r.fail(entry["name"], "name: '" + c.name + "' is also " + o.label + "'s");
        }
        for (const Held& m : mine.listeners) {
            for (const Held& h : t.listeners) {
                if (!same_listener(m, h)) continue;
                check_one_protocol(r, entry, m, h, o.label + "'s");
                if (m.carrier == Carrier::Serial) {
                    check_line_agrees(r, entry, m, h, o);
                } else {
                    check_net_agrees(r, entry, m, h, o);
                }
                // The console names PLCs, not unit IDs: its PLCs may have any stations.
                if (m.protocol != "http") {
                    check_units(r, entry, c, o, listener_words(m),
                                m.protocol.rfind("modbus", 0) == 0);
                }
            }
        }
        if (mine.state_file.empty() || t.state_file.empty()) continue;
        // Paths are quoted whole up to a length real ones do not reach.
        constexpr std::size_t kPath = 1024;
        const Position& at = t.state_at;
        const std::string other = "('" + excerpt(default_state_file(o), kPath) + "' at " +
                                  at.file.str() + ":" + std::to_string(at.line) + ":" +
                                  std::to_string(at.column);
        if (mine.state_file == t.state_file) {
            r.fail(where(entry, {"persistence", "file"}),
                   "persistence.file: '" + excerpt(default_state_file(c), kPath) + "' is also " +
                       o.label + "'s state file " + other + "; both are " +
                       excerpt(mine.state_file, kPath) + ")");
        }
        // A state file has two companions beside it, its lock and the temporary it is made
        // through (docs/operations.md, "Retentive memory"): another's file may be neither.
        for (const std::string_view companion : kStateCompanions) {
            const std::string suffix(companion);
            if (mine.state_file == t.state_file + suffix ||
                t.state_file == mine.state_file + suffix) {
                std::string why = "persistence.file: '";
                why.append(excerpt(default_state_file(c), kPath)).append("' and ");
                why.append(o.label).append("'s state file ").append(other);
                why.append(") differ only by '").append(suffix).append("', the name of a ");
                why.append(suffix == ".new" ? "state file's temporary" : "state file's lock");
                why.append(": a start would take the other's file for its own");
                r.fail(where(entry, {"persistence", "file"}), why);
            }
        }
    }
}

// Runs `read` with an error list, then throws every error it recorded (with the one that ended
// it, if one did), in the order of the file; returns what it read when there was none.
template <class Read>
auto collecting(Read read) {
    Errors errors;
    decltype(read(errors)) out{};
    errors.attempt([&] { out = read(errors); });
    errors.raise();
    return out;
}

// The per-PLC keys of a single-PLC file, refused beside `plcs:`.
bool per_plc_key(const std::string& key) {
    if (key == "log" || key == "http") return false;
    if (std::find(kCommonSections.begin(), kCommonSections.end(), key) != kCommonSections.end())
        return true;
    for (const Family* p : families()) {
        const auto s = p->sections();
        if (std::find(s.begin(), s.end(), key) != s.end()) return true;
    }
    return false;
}

// `plcs:` — a list of entries, each a single-PLC config with an optional `name:`; only `log:`
// and `http:` may stand beside it.
// `doc` is the file, `root` its tree without the entries, which are made one at a time: 5,000
// entries as one tree would take more memory than the PLCs they describe.
// A damaged state file is moved aside as NAME.bad-YYYYmmdd-HHMMSS-N, and NAME.lock and NAME.new
// lie beside it: the state file's name, given or made from the config's and the entry's, must
// leave them room in the file system's 255 bytes.
void check_state_file_name(const Reader& r, const Node& at, const Config& c) {
    if (!c.persistence.enabled) return;
    constexpr std::size_t kMaxName = 230;
    const std::string name = std::filesystem::path(default_state_file(c)).filename().string();
    if (name.size() <= kMaxName) return;
    std::string why = "persistence.file: the state file's name (after the last '/') is ";
    why += std::to_string(name.size());
    why +=
        " bytes long; at most 230, as the daemon names files after it "
        "(NAME.bad-YYYYmmdd-HHMMSS)";
    if (c.persistence.file.empty()) why += "; it is made from the config's file name: give one";
    r.fail(at, why);
}

std::vector<Config> read_plcs(const YamlDocument& doc,
                              const Node& root,
                              const std::string& file,
                              const Overrides& overrides,
                              Errors& errors) {
    Reader top(errors);
    for (const auto& [key, value] : root.entries) {
        if (key.is_scalar() && per_plc_key(key.text)) {
            top.report(
                key,
                key.text +
                    ": belongs to one PLC; beside 'plcs:' only 'log:' and 'http:' may stand, so "
                    "move it into each entry of plcs:");
        }
    }
    // The other keys, checked by name only (a key refused above is refused once).
    Node rest;
    rest.kind = Node::Kind::Map;
    rest.pos = root.pos;
    for (const auto& [key, value] : root.entries) {
        if (!key.is_scalar() || !per_plc_key(key.text)) rest.entries.push_back({key, Node{}});
    }
    top.check_keys(rest, "config", {"plcs", "log", "http"});
    const Node& list = root["plcs"];
    if (!list.is_sequence() || doc.items() == 0) {
        top.fail(list, "plcs: expected a list of PLC configs, each with at least 'profile:'");
    }
    // Before any entry takes them: with them, the entries' listeners would clash.
    if (overrides.port) top.fail(list, "--port: a config with plcs: sets each PLC's port itself");
    if (overrides.http_port == 0) {
        top.fail(list,
                 "--http-port 0: with plcs: each PLC would get a console of its own on a "
                 "port of the kernel's choosing; give a port");
    }
    LogConfig log;
    section(top, root, "log", read_log, log);
    // `http:` beside `plcs:` is one console for every PLC that has no `http:` of its own.
    std::optional<TcpConfig> http;
    top.attempt([&] { read_http(top, root["http"], http, overrides.http_port.has_value()); });
    if (http && http->port == 0 && !overrides.http_port) {
        // As --http-port 0: one console for every PLC cannot be "any free port" for each.
        top.fail(root["http"]["port"],
                 "http.port: 0 beside plcs: each PLC would get a console of its own on a port "
                 "of the kernel's choosing; give a port");
    }
    std::vector<Config> out;
    std::vector<Taken> taken;
    Clashes clashes;
    out.reserve(doc.items());
    taken.reserve(doc.items());
    // Each entry on its own: the errors of one are recorded, named by it, and the next is read.
    for (std::size_t i = 0; i < doc.items(); ++i) {
        const Node e = doc.item(i);
        std::string label = "plcs[" + std::to_string(i) + "]";
        Reader r(errors);
        const std::size_t errors_before = errors.size();
        errors.set_prefix(label + ": ");
        errors.attempt([&] {
            std::string name;
            if (e.is_map() && e["name"]) {
                name = r.scalar(e["name"], "name");
                if (!valid_entry_name(name)) {
                    r.fail(e["name"], "name: expected 1 to 32 letters, digits, '_' or '-', got '" +
                                          excerpt(name) + "'");
                }
                // The console's and the API's paths name a PLC by its name or its position:
                // a name "1" would hide the second entry, or be hidden by it.
                if (name.find_first_not_of("0123456789") == std::string::npos) {
                    r.fail(e["name"], "name: '" + name +
                                          "' is digits alone, which the console reads as an "
                                          "entry's position in plcs:; give it a letter");
                }
                label += " (" + name + ")";
                errors.set_prefix(label + ": ");
            }
            Config c = read_root(r, e, overrides, true);
            // Compared with the other entries only when it is whole: a key in error would
            // only be refused again as a clash.
            if (errors.size() != errors_before) return;
            c.path = file;
            c.name = std::move(name);
            c.label = label;
            c.index = static_cast<int>(i);
            c.log = log;
            if (!e["http"]) {
                // The console beside `plcs:`, and what the command line sets of it; checked
                // against the entry's own listeners as those were.
                c.http = http;
                Overrides console;
                console.http_port = overrides.http_port;
                apply(console, c);
                check_own_listeners(r, e, c, console);
            }
            c.fingerprint = fingerprint(c, e, e["http"] ? nullptr : &root["http"]);
            check_state_file_name(r, where(e, {"persistence", "file"}), c);
            Taken mine(c, e);
            check_shared(r, e, c, mine, out, taken, clashes);
            clashes.add(out.size(), c, mine);
            taken.push_back(std::move(mine));
            out.push_back(std::move(c));
        });
    }
    errors.set_prefix("");
    return out;
}

}  // namespace

std::string plc_id(const Config& config) {
    if (config.index < 0) return "";
    return config.name.empty() ? "plcs[" + std::to_string(config.index) + "]" : config.name;
}

std::string default_state_file(const Config& config) {
    if (!config.persistence.file.empty()) return config.persistence.file;
    const auto slash = config.path.rfind('/');
    std::string stem = slash == std::string::npos ? config.path : config.path.substr(slash + 1);
    const auto dot = stem.rfind('.');
    if (dot != std::string::npos && dot > 0) stem.erase(dot);
    if (stem.empty()) stem = "plcemud";
    if (config.index >= 0) {
        stem += '-';
        stem += config.name.empty() ? std::to_string(config.index) : config.name;
    }
    return stem + ".state";
}

Config parse_config(const std::string& text, const std::string& name) {
    return read_config(parse_yaml_tree(text, name), name);
}

Config read_config(const Node& root, const std::string& name, const Overrides& overrides) {
    if (root.is_map() && root["plcs"]) {
        Reader r;
        r.fail(root["plcs"], "plcs: this command takes a config holding one PLC");
    }
    Config c = collecting([&](Errors& errors) {
        Reader r(errors);
        return read_root(r, root, overrides);
    });
    c.path = name;
    c.fingerprint = fingerprint(c, root, nullptr);
    const Reader r;
    check_state_file_name(r, where(root, {"persistence", "file"}), c);
    return c;
}

Config load_config(const std::string& path) { return parse_config(read_config_file(path), path); }

std::vector<Config> parse_plcs(const std::string& text,
                               const std::string& name,
                               const Overrides& overrides) {
    YamlDocument doc(text, name);
    const Node root = doc.tree_without_items("plcs");
    if (root.is_map() && root["plcs"]) {
        return collecting(
            [&](Errors& errors) { return read_plcs(doc, root, name, overrides, errors); });
    }
    std::vector<Config> one;
    one.push_back(read_config(root, name, overrides));
    return one;
}

std::vector<Config> load_plcs(const std::string& path, const Overrides& overrides) {
    return parse_plcs(read_config_file(path), path, overrides);
}

}  // namespace plcemu::config
