#include "profiles/vb/settings.hpp"

#include <string>

#include "plcemu/profiles/profile.hpp"
#include "profiles/vb/file_registers.hpp"
#include "profiles/vb/mbus_config.hpp"

namespace plcemu::profiles::vb {

std::shared_ptr<const Settings> read_settings(const config::Config& config,
                                              const config::Reader& r) {
    auto s = std::make_shared<Settings>();
    // Named references, not a structured binding: clang 14 cannot capture one in a lambda.
    for (const auto& section : config.sections) {
        const std::string& name = section.first;
        const config::Node& node = section.second;
        if (name == "modules") {
            r.attempt([&] { s->modules = read_modules(r, node); });
        } else if (name == "file_registers" && !node.is_null()) {
            r.attempt([&] { s->file_registers = read_file_registers(r, node); });
        }
    }
    r.attempt([&] { s->mbus = read_mbus(config, r); });
    return s;
}

std::shared_ptr<const Settings> settings_of(const config::Config& config) {
    return profiles::settings_of<Settings>(config, &read_settings);
}

}  // namespace plcemu::profiles::vb
