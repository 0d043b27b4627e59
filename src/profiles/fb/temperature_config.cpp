#include "profiles/fb/temperature_config.hpp"

#include <array>
#include <charconv>

#include "plcemu/config/reader.hpp"
#include "plcemu/image/excerpt.hpp"
#include "plcemu/profiles/profile.hpp"

namespace plcemu::profiles::fb {

namespace {

using image::excerpt;

// The FB-2A…4 modules by their FUN72/FUN73 Tp code (FB manual FUN73, operand Tp).
constexpr std::array<std::string_view, 6> kSlim{"FB-2AK4", "FB-2AJ4",   "FB-2AH4",
                                                "FB-2AT4", "FB-2AH4-3", "FB-2AT4-3"};
// At most 8 slim modules (Sm = 0, 4, …, 28).
constexpr std::size_t kMaxSlim = 8;

// FB-4AJxx / FB-4AKxx, xx = 12, 16, 18 or 24 (FB manual FUN86: "xx may be 12,16,24"; the FB
// manual's chapter 20 lists 18 too).
std::optional<TemperatureModule> multiplexed(std::string_view s) {
    constexpr std::string_view kPrefix = "FB-4A";
    if (s.size() != kPrefix.size() + 3 || s.substr(0, kPrefix.size()) != kPrefix) return {};
    const char type = s[kPrefix.size()];
    if (type != 'J' && type != 'K') return {};
    int points = 0;
    const char* first = s.data() + kPrefix.size() + 1;
    const auto [end, ec] = std::from_chars(first, s.data() + s.size(), points);
    if (ec != std::errc{} || end != s.data() + s.size()) return {};
    if (points != 12 && points != 16 && points != 18 && points != 24) return {};
    TemperatureModule m;
    m.multiplexed = true;
    m.sensor = type == 'K' ? 0 : 1;
    m.points = points;
    return m;
}

std::optional<TemperatureModule> module(std::string_view s) {
    for (std::size_t tp = 0; tp < kSlim.size(); ++tp) {
        if (kSlim[tp] == s) {
            TemperatureModule m;
            m.sensor = static_cast<int>(tp);
            return m;
        }
    }
    return multiplexed(s);
}

// One `temperature.modules` entry, checked against the modules before it.
TemperatureModule module(const config::Reader& r,
                         const config::Node& e,
                         const std::vector<TemperatureModule>& before,
                         std::size_t& slim) {
    const std::string s = r.scalar(e, "temperature.modules entry");
    std::optional<TemperatureModule> m = module(s);
    if (!m) {
        r.fail(e, "temperature.modules: unknown module '" + excerpt(s) +
                      "' (expected FB-2AK4, FB-2AJ4, FB-2AH4, FB-2AT4, FB-2AH4-3, FB-2AT4-3, "
                      "or FB-4AJ/FB-4AK with 12, 16, 18 or 24 points)");
    }
    m->name = s;
    m->pos = r.pos(e);
    // FB manual FUN73: the FB-2A…4 cannot be used with the FB-4AJ(K)xx, and an FB-4AJ(K)xx
    // is used alone.
    for (const auto& other : before) {
        if (other.multiplexed || m->multiplexed) {
            r.fail(e, "temperature.modules: " + s + " cannot be used together with the " +
                          other.name + " at " + position_text(other.pos) +
                          " (an FB-4AJ(K)xx is used alone, without FB-2A…4 modules)");
        }
    }
    if (!m->multiplexed && ++slim > kMaxSlim) {
        r.fail(e, "temperature.modules: at most 8 FB-2A…4 modules (32 points)");
    }
    return *m;
}

// Each key and each module entry on its own: an error in one is recorded and the others are
// still read (docs/configuration.md, "Configuration").
void read(const config::Reader& r, const config::Node& n, TemperatureConfig& t) {
    r.check_keys(n, "temperature", {"modules", "table", "scan_rate"});
    // The FBs configuration table and its conversion rate: an FB measures with instructions.
    for (const char* key : {"table", "scan_rate"}) {
        if (n[key]) {
            r.report(n[key], std::string("temperature.") + key +
                                 " is not valid in profile fb (the FB measures with the TP4, "
                                 "TSTC and TPSNS instructions; temperature.modules lists its "
                                 "modules)");
        }
    }
    const auto& list = n["modules"];
    if (!list) return;
    if (!list.is_sequence())
        r.fail(list, "temperature.modules: expected a list such as [FB-2AK4, FB-2AK4]");
    std::size_t slim = 0;
    for (const auto& e : list.items) {
        r.attempt([&] { t.modules.push_back(module(r, e, t.modules, slim)); });
    }
}

}  // namespace

const TemperatureModule* multiplexed_module(const std::vector<TemperatureModule>& modules) {
    for (const auto& m : modules) {
        if (m.multiplexed) return &m;
    }
    return nullptr;
}

std::string position_text(const config::Position& p) {
    return p.file.str() + ":" + std::to_string(p.line) + ":" + std::to_string(p.column);
}

std::string declared_at(const TemperatureModule& module) { return position_text(module.pos); }

std::shared_ptr<const Settings> read_settings(const config::Config& config,
                                              const config::Reader& r) {
    auto s = std::make_shared<Settings>();
    read_section(config, r, "temperature", &read, s->temperature);
    return s;
}

std::shared_ptr<const Settings> settings_of(const config::Config& config) {
    return profiles::settings_of<Settings>(config, &read_settings);
}

}  // namespace plcemu::profiles::fb
