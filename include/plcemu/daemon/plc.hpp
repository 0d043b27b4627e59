#pragma once
// One emulated PLC built from a config: image, engine with its program and subsystems, and the
// Modbus units and dispatcher. No event loop here: the daemon, the tests, the fuzzers and the
// benchmarks all build this.

#include <memory>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "plcemu/config/config.hpp"
#include "plcemu/engine/engine.hpp"
#include "plcemu/image/image.hpp"
#include "plcemu/modbus/address_map.hpp"
#include "plcemu/modbus/dispatcher.hpp"
#include "plcemu/modbus/plc_unit.hpp"
#include "plcemu/plant/plant.hpp"

namespace plcemu::daemon {

/// How a Plc takes over its storage (docs/operations.md, "Retentive memory").
enum class Start : std::uint8_t {
    Fresh,     ///< new storage (all zero): presets applied, power-up counted
    Retained,  ///< storage from an earlier run: non-retentive devices cleared, power-up counted,
               ///< presets on retentive devices only with persistence.init = always
    Reload,    ///< the live image of a running PLC (SIGHUP): nothing cleared, no power-up,
               ///< presets as for Retained
};

/// The layout of a config: the profile's areas, its retentive ranges (or the config's), and
/// what the profile keeps in any case (a power-up counter).
image::Layout plc_layout(const config::Config& config);

/// The config's program built with its profile's instruction table (throws config::ConfigError).
/// With `operands`, its device operands are described there (the tag export); with `warnings`,
/// what is suspect in it that still runs (a coil driven twice in an instruction list) is added
/// there, each "file:line:col: message".
engine::Program build_program(const config::Config& config,
                              engine::Tags* operands = nullptr,
                              std::vector<std::string>* warnings = nullptr);

/// The config's program as --print-program shows it: one statement a line, its step number
/// first (an instruction list as the family writes it; entries as their mnemonic and operands).
std::string print_program(const config::Config& config);

/// How the plant of a config starts: `plant:` with its per-channel overrides, each channel driven
/// by its `drive` or else by the output the program declares for it.
plant::PlantSetup plant_setup(const config::Config& config, const engine::Declarations& program);

/// The map of a config's `modbus.map`, or null when the config keeps the profile's map.
std::unique_ptr<modbus::AddressMap> map_of(const config::Config& config);

/// The PLC of a config.
class Plc {
public:
    /// Builds everything; throws config::ConfigError for what the config loader could not see
    /// (operands, presets out of range). With `storage`, the image lives there (a state file)
    /// and `start` says what it holds; otherwise the image is its own and starts cleared.
    /// `program`, when given, is the config's program already built (a reload builds it off the
    /// event loop). `kept`, with Start::Retained, is where the storage kept values: the ranges
    /// retentive when it was last used (StateFile::retentive_before); a device retentive now
    /// but not then was cleared, and takes its preset. Without it, every retentive device kept
    /// its value.
    explicit Plc(const config::Config& config,
                 std::span<std::byte> storage = {},
                 Start start = Start::Retained,
                 std::optional<engine::Program> program = std::nullopt,
                 std::optional<std::vector<image::Range>> kept = std::nullopt);
    /// The same, sharing the config instead of copying it (a reload's config may be large).
    explicit Plc(std::shared_ptr<const config::Config> config,
                 std::span<std::byte> storage = {},
                 Start start = Start::Retained,
                 std::optional<engine::Program> program = std::nullopt,
                 std::optional<std::vector<image::Range>> kept = std::nullopt);
    ~Plc();

    /// The register image.
    image::Image& image() { return *image_; }
    /// The scan engine.
    engine::Engine& engine() { return *engine_; }
    /// The PLC's Modbus unit.
    modbus::PlcUnit& unit() { return *unit_; }
    /// The PLC's Modbus function codes and identity.
    modbus::Dispatcher& dispatcher() { return *dispatcher_; }
    /// The config it was built from.
    const config::Config& config() const { return *config_; }
    /// The config, shared.
    const std::shared_ptr<const config::Config>& shared_config() const { return config_; }
    /// The plant (docs/simulator-and-plant.md), owned by the engine.
    plant::Plant& plant() { return *plant_; }

    /// Applies the config's `init:` presets to the image (done at construction), sparing
    /// retained values as the Start and persistence.init say.
    void apply_init();

private:
    std::shared_ptr<const config::Config> config_;
    Start start_ = Start::Fresh;
    std::optional<std::vector<image::Range>> kept_;
    std::unique_ptr<image::Image> image_;
    std::unique_ptr<engine::Engine> engine_;
    std::unique_ptr<modbus::AddressMap> map_;
    std::unique_ptr<modbus::PlcUnit> unit_;
    std::unique_ptr<modbus::Dispatcher> dispatcher_;
    plant::Plant* plant_ = nullptr;
};

/// The emulator's version string.
const char* version();

}  // namespace plcemu::daemon
