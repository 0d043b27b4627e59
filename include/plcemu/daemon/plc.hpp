#pragma once
// One emulated PLC built from a config: image, engine with its program and subsystems, and the
// Modbus units and dispatcher. No event loop here: the daemon, the tests, the fuzzers and the
// benchmarks all build this.

#include <memory>
#include <span>

#include "plcemu/config/config.hpp"
#include "plcemu/engine/engine.hpp"
#include "plcemu/image/image.hpp"
#include "plcemu/modbus/dispatcher.hpp"
#include "plcemu/modbus/plc_unit.hpp"

namespace plcemu::daemon {

/// The PLC of a config.
class Plc {
public:
    /// Builds everything; throws config::ConfigError for what the config loader could not see
    /// (operands, presets out of range). With `storage`, the image lives there (a state file)
    /// and keeps its retentive ranges; otherwise it starts cleared.
    explicit Plc(const config::Config& config, std::span<std::byte> storage = {});
    ~Plc();

    /// The register image.
    image::Image& image() { return *image_; }
    /// The scan engine.
    engine::Engine& engine() { return *engine_; }
    /// The PLC's Modbus unit.
    modbus::PlcUnit& unit() { return *unit_; }
    /// The request dispatcher.
    modbus::Dispatcher& dispatcher() { return *dispatcher_; }
    /// The config it was built from.
    const config::Config& config() const { return config_; }

    /// Applies the config's `init:` presets to the image (done at construction).
    void apply_init();

private:
    config::Config config_;
    std::unique_ptr<image::Image> image_;
    std::unique_ptr<engine::Engine> engine_;
    std::unique_ptr<modbus::PlcUnit> unit_;
    std::unique_ptr<modbus::Dispatcher> dispatcher_;
};

/// The emulator's version string.
const char* version();

}  // namespace plcemu::daemon
