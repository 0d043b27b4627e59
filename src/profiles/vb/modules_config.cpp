#include "profiles/vb/modules_config.hpp"

#include <array>
#include <string>

#include "plcemu/plant/plant.hpp"
#include "plcemu/profiles/profile.hpp"

namespace plcemu::profiles::vb {

namespace {

using image::excerpt;

struct Type {
    const char* name;
    int channels;
    Sensor sensor;
};

// VB manual, thermal control pages: "The VB series PLC provide various thermometer module".
constexpr std::array<Type, 4> kTypes{{{"VB-8T", 8, Sensor::Thermocouple},
                                      {"VB-4T", 4, Sensor::Thermocouple},
                                      {"VB-4PT", 4, Sensor::Pt100},
                                      {"VB-2PT", 2, Sensor::Pt100}}};

ModuleConfig module(const config::Reader& r, const config::Node& e) {
    const config::Node& type = e.is_map() ? e["type"] : e;
    if (e.is_map()) {
        r.check_keys(e, "modules entry", {"type", "mode"});
        if (!type) r.fail(e, "modules entry: 'type' is required");
    }
    const std::string name = r.scalar(type, "modules.type");
    ModuleConfig m;
    m.pos = e.pos;
    for (const Type& t : kTypes) {
        if (name == t.name) {
            m.type = t.name;
            m.channels = t.channels;
            m.sensor = t.sensor;
        }
    }
    if (m.channels == 0) {
        r.fail(type, "modules.type: unknown module '" + excerpt(name) +
                         "' (expected VB-8T, VB-4T, VB-4PT or VB-2PT)");
    }
    // Mode 7 is the manual's K type, 0.1 °C; a Pt100 module reads in 0.1 °C at any non-zero
    // code (docs/profile-vb.md, "Temperature modules").
    m.mode = m.sensor == Sensor::Thermocouple ? 7 : 1;
    if (e.is_map() && e["mode"]) {
        m.mode = static_cast<std::uint16_t>(r.integer(e["mode"], "modules.mode", 0, 32767));
    }
    return m;
}

}  // namespace

std::vector<ModuleConfig> read_modules(const config::Reader& r, const config::Node& section) {
    std::vector<ModuleConfig> out;
    if (section.is_null()) return out;
    if (!section.is_sequence()) {
        r.fail(section, "modules: expected a list such as [VB-8T, {type: VB-4PT, mode: 1}]");
    }
    int channels = 0;
    for (const auto& e : section.items) {
        if (!r.attempt([&] { out.push_back(module(r, e)); })) continue;
        channels += out.back().channels;
        // Past a bound the entries after it add nothing: one error, where it is crossed.
        if (out.size() > kMaxModules) {
            r.report(e, "modules: at most " + std::to_string(kMaxModules) + " modules");
            break;
        }
        // Each channel is one channel of the plant, numbered across modules.
        if (channels > plant::kChannels) {
            r.report(e, "modules: more than " + std::to_string(plant::kChannels) +
                            " channels in all (the plant has " + std::to_string(plant::kChannels) +
                            ")");
            break;
        }
    }
    return out;
}

}  // namespace plcemu::profiles::vb
