#pragma once
// The FB `temperature:` section: the temperature modules of the emulated expansion chain, in
// order (FB manual FUN72/FUN73 and FUN85/FUN86; docs/profile-fb.md, "Temperature modules").

#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "plcemu/config/config.hpp"
#include "plcemu/config/family.hpp"
#include "plcemu/config/reader.hpp"

namespace plcemu::profiles::fb {

/// One temperature module of the chain.
struct TemperatureModule {
    std::string name;          ///< as written: "FB-2AK4", "FB-4AK24"
    bool multiplexed = false;  ///< an FB-4AJ(K)xx (FUN85 TPSNS), not an FB-2A…4 (FUN72/FUN73)
    int sensor = 0;            ///< FB-2A…4: the Tp code 0–5; FB-4A: 0 K, 1 J (TPSNS's tp)
    int points = 4;            ///< 4, or the FB-4A's 12, 16, 18 or 24
    config::Position pos;      ///< where it was declared
};

/// `temperature`
struct TemperatureConfig {
    std::vector<TemperatureModule> modules;  ///< in chain order; empty: what the program says
};

/// The FB-4AJ(K)xx of a chain, or null (a chain with one has nothing else).
const TemperatureModule* multiplexed_module(const std::vector<TemperatureModule>& modules);

/// "file:line:col" of a position.
std::string position_text(const config::Position& pos);

/// "file:line:col" of a module's entry.
std::string declared_at(const TemperatureModule& module);

/// What the FB reads from its own sections at load: its `temperature:` section.
struct Settings final : config::ProfileSettings {
    TemperatureConfig temperature;  ///< empty when the config has no `temperature:`
};

/// Reads the `temperature:` section of `config` with `r`: each key and each module entry on its
/// own, an error recorded where `r` records errors (else thrown) and the reading going on.
std::shared_ptr<const Settings> read_settings(const config::Config& config,
                                              const config::Reader& r);

/// The settings of a config (profiles::settings_of).
std::shared_ptr<const Settings> settings_of(const config::Config& config);

}  // namespace plcemu::profiles::fb
