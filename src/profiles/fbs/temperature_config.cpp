#include "profiles/fbs/temperature_config.hpp"

#include <algorithm>
#include <map>
#include <string>

#include "plcemu/profiles/profile.hpp"

namespace plcemu::profiles::fbs {

namespace {

using image::excerpt;

std::uint8_t module_code(const std::string& name) {
    static const std::map<std::string, std::uint8_t> kNames{
        {"TC6", 1}, {"RTD6", 2}, {"TC16", 3}, {"RTD16", 4}, {"TC2", 5}};
    auto it = kNames.find(name);
    return it == kNames.end() ? 0 : it->second;
}

bool sensor_code(std::uint8_t module, const std::string& s, std::uint8_t& out) {
    static const std::map<std::string, std::uint8_t> kTc{{"J", 0}, {"K", 1}, {"T", 2}, {"E", 3},
                                                         {"N", 4}, {"B", 5}, {"R", 6}, {"S", 7}};
    static const std::map<std::string, std::uint8_t> kRtd{
        {"PT100_DIN", 0}, {"PT100_JIS", 1}, {"PT1000_DIN", 2}, {"PT1000_JIS", 3}};
    std::string u;
    for (char c : s) u += static_cast<char>(c >= 'a' && c <= 'z' ? c - 'a' + 'A' : c);
    const bool rtd = module == 2 || module == 4;
    const auto& m = rtd ? kRtd : kTc;
    auto it = m.find(u);
    if (it == m.end()) return false;
    out = it->second;
    return true;
}

// One `temperature.modules` entry such as "TC6:K".
ModuleConfig module(const config::Reader& r, const config::Node& e) {
    const std::string s = r.scalar(e, "temperature.modules entry");
    const auto colon = s.find(':');
    ModuleConfig mc;
    mc.pos = r.pos(e);
    mc.name_code = module_code(s.substr(0, colon));
    if (mc.name_code == 0) {
        r.fail(e, "temperature.modules: unknown module '" + excerpt(s.substr(0, colon)) +
                      "' (expected TC6, RTD6, TC16, RTD16 or TC2)");
    }
    const bool rtd = mc.name_code == 2 || mc.name_code == 4;
    const std::string sensor =
        colon == std::string::npos ? (rtd ? "PT100_DIN" : "K") : s.substr(colon + 1);
    if (!sensor_code(mc.name_code, sensor, mc.sensor_type)) {
        r.fail(e, "temperature.modules: unknown sensor '" + excerpt(sensor) + "' (expected " +
                      (rtd ? "PT100_DIN, PT100_JIS, PT1000_DIN or PT1000_JIS"
                           : "J, K, T, E, N, B, R or S") +
                      ")");
    }
    return mc;
}

// Each key and each module entry on its own: an error in one is recorded and the others are
// still read (docs/configuration.md, "Configuration").
void read(const config::Reader& r, const config::Node& n, TemperatureConfig& t) {
    r.check_keys(n, "temperature", {"table", "modules", "scan_rate"});
    r.attempt([&] {
        if (!n["table"]) return;
        const image::Device table = r.device(n["table"], "temperature.table");
        if (table.word_of_bits || (table.area != image::Area::R && table.area != image::Area::D)) {
            r.fail(n["table"], "temperature.table: expected an R or D register");
        }
        t.table = table;
    });
    r.attempt([&] {
        const auto& m = n["modules"];
        if (!m) return;
        if (!m.is_sequence())
            r.fail(m, "temperature.modules: expected a list such as [TC6:K, RTD6:PT100_DIN]");
        for (const auto& e : m.items) r.attempt([&] { t.modules.push_back(module(r, e)); });
        if (t.modules.size() > 8) r.fail(m, "temperature.modules: at most 8 modules");
    });
    r.attempt([&] {
        if (!n["scan_rate"]) return;
        const std::string s = r.scalar(n["scan_rate"], "temperature.scan_rate");
        if (s != "normal" && s != "fast")
            r.fail(n["scan_rate"], "temperature.scan_rate: expected 'normal' or 'fast'");
        t.fast = s == "fast";
    });
}

}  // namespace

std::shared_ptr<const Settings> read_settings(const config::Config& config,
                                              const config::Reader& r) {
    auto s = std::make_shared<Settings>();
    read_section(config, r, "temperature", &read, s->temperature);
    // The table's four words and one per module (at least one: SR+1 is 1-8) must be registers
    // the PLC has (FBs manual §21.3.1): R8071 or R4165 would leave it never valid.
    if (const auto& table = s->temperature.table) {
        const std::uint32_t words =
            4 + static_cast<std::uint32_t>(std::max<std::size_t>(1, s->temperature.modules.size()));
        const image::Range r_table{table->area, table->index, words};
        if (!of(config).layout().contains(r_table)) {
            for (const auto& section : config.sections) {
                if (section.first != "temperature") continue;
                const config::Node& node = section.second;
                r.attempt([&] {
                    r.fail(node["table"], "temperature.table: " + r.naming().format_range(r_table) +
                                              " (" + std::to_string(words) +
                                              " words: SR+0 to SR+3 and one per module) are not "
                                              "all registers of this PLC");
                });
            }
        }
    }
    return s;
}

std::shared_ptr<const Settings> settings_of(const config::Config& config) {
    return profiles::settings_of<Settings>(config, &read_settings);
}

}  // namespace plcemu::profiles::fbs
