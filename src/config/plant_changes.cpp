// What a reload changes in `plant:` (config::plant_changes), key by key.

#include <sstream>

#include "plcemu/config/config.hpp"

namespace plcemu::config {

namespace {

std::string text(double v, const image::Naming& /*naming*/) {
    std::ostringstream o;
    o << v;
    return o.str();
}

std::string text(bool v, const image::Naming& /*naming*/) { return v ? "true" : "false"; }

std::string text(const std::optional<int>& v, const image::Naming& /*naming*/) {
    return v ? std::to_string(*v) : "default";
}

std::string text(const std::optional<image::Device>& v, const image::Naming& naming) {
    return v ? naming.format_device(v->area, v->index) : "default";
}

// The keys of one channel (`plant.defaults` or `plant.channels.N`) that differ. With
// `inherited`, the defaults before and after: a key equal to the default on both sides only
// follows it, and the defaults' own line says so.
void channel_changes(const std::string& prefix,
                     const ChannelConfig& x,
                     const ChannelConfig& y,
                     const std::pair<const ChannelConfig*, const ChannelConfig*>& inherited,
                     const image::Naming& naming,
                     std::vector<std::string>& out) {
    auto cmp = [&](const char* key, auto get) {
        const auto a = get(x);
        const auto b = get(y);
        if (a == b) return;
        if (inherited.first != nullptr && get(*inherited.first) == a &&
            get(*inherited.second) == b) {
            return;
        }
        out.push_back(prefix + key + ": " + text(a, naming) + " -> " + text(b, naming));
    };
    cmp("ambient", [](const ChannelConfig& c) { return c.params.ambient_c; });
    cmp("k", [](const ChannelConfig& c) { return c.params.k_c; });
    cmp("tau", [](const ChannelConfig& c) { return c.params.tau_s; });
    cmp("dead_time", [](const ChannelConfig& c) { return c.params.dead_time_s; });
    cmp("noise", [](const ChannelConfig& c) { return c.params.noise_c; });
    cmp("cooling", [](const ChannelConfig& c) { return c.params.cooling; });
    cmp("lead_resistance", [](const ChannelConfig& c) { return c.params.lead_ohm; });
    cmp("drive", [](const ChannelConfig& c) { return c.drive; });
    cmp("drive_full_scale", [](const ChannelConfig& c) { return c.drive_full_scale; });
    cmp("faults.sensor_broken", [](const ChannelConfig& c) { return c.faults.sensor_broken; });
    cmp("faults.heater_open", [](const ChannelConfig& c) { return c.faults.heater_open; });
    cmp("faults.heater_shorted", [](const ChannelConfig& c) { return c.faults.heater_shorted; });
    cmp("faults.reading_frozen", [](const ChannelConfig& c) { return c.faults.reading_frozen; });
}

const ChannelConfig* channel(const PlantConfig& p, int index) {
    for (const auto& [i, c] : p.channels) {
        if (i == index) return &c;
    }
    return nullptr;
}

}  // namespace

std::vector<std::string> plant_changes(const PlantConfig& before,
                                       const PlantConfig& after,
                                       const image::Naming& naming) {
    std::vector<std::string> out;
    channel_changes("plant.defaults.", before.defaults, after.defaults, {nullptr, nullptr}, naming,
                    out);
    for (const auto& [i, c] : after.channels) {
        const std::string name = "plant.channels." + std::to_string(i);
        if (const ChannelConfig* was = channel(before, i)) {
            channel_changes(name + ".", *was, c, {&before.defaults, &after.defaults}, naming, out);
        } else {
            out.push_back(name + ": added");
        }
    }
    for (const auto& [i, c] : before.channels) {
        if (channel(after, i) == nullptr) {
            out.push_back("plant.channels." + std::to_string(i) + ": removed");
        }
    }
    if (before.seed != after.seed) {
        out.push_back("plant.seed: " + std::to_string(before.seed) + " -> " +
                      std::to_string(after.seed));
    }
    return out;
}

}  // namespace plcemu::config
