#pragma once
// The FBs `temperature:` section: where the temperature configuration table is and which
// temperature modules the expansion chain holds (FBs manual §21.3; docs/profile-fbs.md,
// "Temperature measurement").

#include <cstdint>
#include <memory>
#include <optional>
#include <vector>

#include "plcemu/config/config.hpp"
#include "plcemu/config/family.hpp"
#include "plcemu/config/reader.hpp"
#include "plcemu/image/area.hpp"

namespace plcemu::profiles::fbs {

/// One installed temperature module of the emulated expansion chain.
struct ModuleConfig {
    std::uint8_t name_code = 0;  ///< 1 TC6, 2 RTD6, 3 TC16, 4 RTD16, 5 TC2
    std::uint8_t sensor_type =
        0;                 ///< sensor type code (docs/profile-fbs.md, "Temperature measurement")
    config::Position pos;  ///< where it was declared
};

/// `temperature`
struct TemperatureConfig {
    std::optional<image::Device> table;  ///< start of the configuration table (R or D)
    std::vector<ModuleConfig> modules;   ///< installed modules, in chain order
    bool fast = false;  ///< "scan rate": fast conversion (half time, 1° resolution)
};

/// What the FBs reads from its own sections at load: its `temperature:` section.
struct Settings final : config::ProfileSettings {
    TemperatureConfig temperature;  ///< empty when the config has no `temperature:`
};

/// Reads the `temperature:` section of `config` with `r`: each key and each module entry on its
/// own, an error recorded where `r` records errors (else thrown) and the reading going on.
std::shared_ptr<const Settings> read_settings(const config::Config& config,
                                              const config::Reader& r);

/// The settings of a config (profiles::settings_of).
std::shared_ptr<const Settings> settings_of(const config::Config& config);

}  // namespace plcemu::profiles::fbs
