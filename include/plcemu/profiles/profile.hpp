#pragma once
// A PLC family as one object: its layout, the spelling of its devices, its Modbus map, the
// special devices it keeps each scan, its identity, its instruction table and the subsystems it
// attaches. The image, the engine, the config loader, the dispatcher and the daemon ask the
// profile; none of them names a family. A profile registers itself (docs/architecture.md,
// "Adding a profile"), and with it the part the config loader reads (config::Family).

#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "plcemu/config/config.hpp"
#include "plcemu/config/family.hpp"
#include "plcemu/config/master.hpp"
#include "plcemu/config/reader.hpp"
#include "plcemu/engine/engine.hpp"
#include "plcemu/engine/sensors.hpp"
#include "plcemu/image/layout.hpp"
#include "plcemu/image/naming.hpp"
#include "plcemu/instructions/instructions.hpp"
#include "plcemu/instructions/listing.hpp"
#include "plcemu/modbus/address_map.hpp"
#include "plcemu/modbus/dispatcher.hpp"

namespace plcemu::profiles {

/// One PLC family. What the config loader asks of it (name, models, station, naming, layout,
/// its own sections and the settings it reads from them) is declared in config::Family.
class Profile : public config::Family {
public:
    /// What it emulates, for --help and logs: "FATEK FBs".
    virtual std::string_view title() const = 0;
    /// A number recorded in state files; never reused for another family.
    virtual std::uint32_t family() const = 0;

    /// Vendor name of FC 11h and FC 2Bh/0Eh.
    virtual std::string_view vendor() const = 0;

    /// Devices retentive whatever the config says (a power-up counter).
    virtual std::vector<image::Range> always_retentive() const { return {}; }

    /// The default Modbus map (a config's `modbus.map` replaces it).
    virtual const modbus::AddressMap& map() const = 0;
    /// Function codes the family adds (a handler) or refuses (nullptr) beyond the standard
    /// table.
    virtual std::vector<std::pair<std::uint8_t, modbus::FunctionHandler>> functions() const {
        return {};
    }

    /// Devices that hold part of the program (the VB's file registers): their `init:` presets
    /// are applied at every start and reload whatever `persistence` says, Modbus writes to them
    /// are refused (exception 02), and no program operand may write them (the profile reserves
    /// them in its services).
    virtual std::vector<image::Range> program_data(const config::Config& /*config*/) const {
        return {};
    }

    /// A register's value that drives a plant channel at full power, when the config names
    /// none (the scale of the family's analog outputs).
    virtual int drive_full_scale() const { return 16383; }

    /// The mnemonics a program may use.
    virtual const instructions::Table& instructions() const = 0;
    /// How the family's programming tool writes a program as an instruction list (its mnemonic
    /// view), or null when the family has none (docs/program-language.md).
    virtual const instructions::Dialect* listing() const { return nullptr; }
    /// What the family offers its instructions while they bind (measurement table, outputs
    /// the program may not drive). Throws config::ConfigError.
    virtual std::unique_ptr<instructions::Services> services(const config::Config& config) const;
    /// The special devices of a PLC of this config.
    virtual std::unique_ptr<engine::Specials> specials(const config::Config& config) const = 0;
    /// Adds the family's measurement subsystems (which sample `sensors`) to an engine whose
    /// plant is already attached. Throws config::ConfigError.
    virtual void attach(engine::Engine& engine,
                        const config::Config& config,
                        engine::SensorSource& sensors) const = 0;
    /// What the family's own devices mean in a PLC of this config whose image is `image` (presets
    /// applied): its special relays and registers and the areas its subsystems read and write
    /// (a measurement table and where it puts its readings), for the tag export.
    virtual engine::Tags tags(const config::Config& /*config*/,
                              const image::Image& /*image*/) const {
        return {};
    }
    /// The Modbus master port a PLC of this config polls other devices through (the daemon
    /// opens it and hands it to the engine as its outbound link), or nothing.
    virtual std::optional<config::MasterConfig> master(const config::Config& /*config*/) const {
        return std::nullopt;
    }
};

/// An instruction of a config's program as the profiles' checks see it: its mnemonic (the
/// instruction table's) and where it stands.
struct ProgramInstruction {
    std::string mnemonic;  ///< "MBUS", "TPSNS", …
    config::Position pos;  ///< where
};

/// The statements of a config's program written as the family's instruction list, read with
/// the profile's dialect. Throws config::ConfigError at the line and column of a line that
/// cannot be read, or of the first line when the profile has no instruction list.
std::vector<instructions::Statement> listing_statements(const config::Config& config);

/// The function instructions of a config's program, whether written as entries or as the
/// family's instruction list (read with the profile's dialect; a listing that cannot be read
/// gives none: building the program reports it, at its line and column).
std::vector<ProgramInstruction> program_instructions(const config::Config& config);

/// The profile named `name`, or null.
const Profile* find(std::string_view name);
/// The profile of a loaded config (its name was checked by the loader).
const Profile& of(const config::Config& config);
/// Every registered profile, by name.
std::vector<const Profile*> all();
/// The name of the profile whose family() is `family`, or "" when none is.
std::string_view family_name(std::uint32_t family);

/// A family's settings (`S`, what its Family::read returns) of a config: those the loader read,
/// cast back (the family knows its own type). A Config built without the loader has none; its
/// sections are read now with `read` and a reader that throws at the first error.
template <class S>
std::shared_ptr<const S> settings_of(const config::Config& config,
                                     std::shared_ptr<const S> (*read)(const config::Config&,
                                                                      const config::Reader&)) {
    if (config.settings) return std::static_pointer_cast<const S>(config.settings);
    return read(config, config::Reader(of(config).naming()));
}

/// Reads the section `name` of a loaded config (Config::sections) into `into` with `read`, each
/// error recorded by `r` (a family's Family::read, for each section it owns).
template <class T>
void read_section(const config::Config& config,
                  const config::Reader& r,
                  std::string_view name,
                  void (*read)(const config::Reader&, const config::Node&, T&),
                  T& into) {
    for (const auto& section : config.sections) {
        if (section.first == name) r.attempt([&] { read(r, section.second, into); });
    }
}

/// Registers a profile at static initialisation: `const Registration reg{instance};` in the
/// profile's own file. It joins the families the config loader knows (config::add_family).
class Registration {
public:
    explicit Registration(const Profile& profile);
};

}  // namespace plcemu::profiles
