#pragma once
// What the VB reads from its own sections at load, as one value: the temperature modules of
// `modules:`, the CP2 port of `mbus:` and the range of `file_registers:` (docs/profile-vb.md).

#include <memory>
#include <optional>
#include <vector>

#include "plcemu/config/config.hpp"
#include "plcemu/config/family.hpp"
#include "plcemu/config/master.hpp"
#include "plcemu/config/reader.hpp"
#include "plcemu/image/area.hpp"
#include "profiles/vb/modules_config.hpp"

namespace plcemu::profiles::vb {

/// The VB's own sections, read.
struct Settings final : config::ProfileSettings {
    std::vector<ModuleConfig> modules;           ///< `modules:`, in bus order; empty without
    std::optional<config::MasterConfig> mbus;    ///< `mbus:`, or nothing
    std::optional<image::Range> file_registers;  ///< `file_registers:`, or nothing

    /// The CP2 port's serial line, when the master uses one.
    std::vector<OwnLine> own_lines() const override {
        if (!mbus || !mbus->rtu || mbus->transport != config::MasterTransport::Rtu) return {};
        return {{"mbus.rtu", &*mbus->rtu}};
    }
};

/// Reads the sections of `config` with `r`: an error is recorded where `r` records errors (else
/// thrown) and the reading goes on with the next key, entry or section.
std::shared_ptr<const Settings> read_settings(const config::Config& config,
                                              const config::Reader& r);

/// The settings of a config (profiles::settings_of).
std::shared_ptr<const Settings> settings_of(const config::Config& config);

}  // namespace plcemu::profiles::vb
