#pragma once
// The FB `temperature:` section: the temperature modules of the emulated expansion chain, in
// order (FB manual FUN72/FUN73 and FUN85/FUN86; docs/profile-fb.md, "Temperature modules").

#include <optional>
#include <string>
#include <vector>

#include "plcemu/config/config.hpp"

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

/// The `temperature:` section of a config (empty when it has none). Throws config::ConfigError
/// at the faulty node.
TemperatureConfig temperature_config(const config::Config& config);

}  // namespace plcemu::profiles::fb
