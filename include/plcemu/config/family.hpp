#pragma once
// What the config loader asks of a PLC family: how it spells devices and models, its areas, its
// largest station and the sections it reads itself. Families register here (a profile does,
// through profiles::Registration), so the loader reads any family's config without including
// the profiles: the dependency points from the profiles to config (docs/architecture.md,
// "Dependencies").

#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include "plcemu/image/layout.hpp"
#include "plcemu/image/naming.hpp"

namespace plcemu::config {

struct Config;
class Reader;

struct RtuConfig;  // config.hpp

/// What a family reads from its own sections at load (Family::read), as one value: each family
/// derives its own and casts back to it (docs/architecture.md, "Adding a profile").
class ProfileSettings {
public:
    virtual ~ProfileSettings() = default;
    /// A serial line one of the family's own ports uses (a Modbus master's), and the section
    /// that names it ("mbus.rtu").
    struct OwnLine {
        std::string_view section;
        const RtuConfig* line;
    };
    /// The serial lines the family's own ports use: a port's line is its own, shared with no
    /// listener and no other port (the loader refuses it at the line's `device`).
    virtual std::vector<OwnLine> own_lines() const { return {}; }
};

/// A PLC family as the loader sees it (profiles::Profile is one).
class Family {
public:
    virtual ~Family() = default;

    /// The config's name of the family: `profile: fbs`.
    virtual std::string_view name() const = 0;
    /// The model when the config names none.
    virtual std::string_view default_model() const = 0;
    /// True when `model` is a model name of the family.
    virtual bool valid_model(std::string_view model) const = 0;
    /// What a model name looks like, for errors: "an FBs model such as FBs-24MC".
    virtual std::string_view model_hint() const = 0;
    /// The largest station number.
    virtual int max_station() const = 0;

    /// How devices and constants are written.
    virtual const image::Naming& naming() const = 0;
    /// Area sizes, holes and default retentive ranges.
    virtual image::Layout layout() const = 0;
    /// The protocols the family speaks besides Modbus, by their config section ("fatek"); the
    /// loader refuses the sections of the others at their line.
    virtual std::vector<std::string_view> protocols() const { return {}; }
    /// True when `protocol` ("fatek") is among protocols().
    bool speaks(std::string_view protocol) const;
    /// Top-level config sections of subsystems the family has (e.g. "temperature"); the loader
    /// refuses the others at their line.
    virtual std::vector<std::string_view> sections() const { return {}; }
    /// Turns those sections of a loaded config (Config::sections) into the family's settings
    /// (Config::settings), with `r`, the loader's reader: as the loader's last step, so that
    /// their errors come with the others, each recorded where it stands (Reader::attempt) and
    /// the reading going on. Null: the family reads no section.
    virtual std::shared_ptr<const ProfileSettings> read(const Config& /*config*/,
                                                        const Reader& /*r*/) const {
        return nullptr;
    }
};

/// Makes `family` known to the loader under its name. Called during static initialisation, in
/// any order; `family` lives as long as the program.
void add_family(const Family& family);
/// The family named `name`, or null.
const Family* find_family(std::string_view name);
/// Every family, by name.
std::vector<const Family*> families();
/// Their names, comma-separated, for messages.
std::string family_names();

}  // namespace plcemu::config
