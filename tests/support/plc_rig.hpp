#pragma once
// Test support: a PLC built from config text, scanned in simulated time, its devices read and
// written directly. The unit tests of a profile or an instruction derive their rig from it,
// adding the config they start from and the helpers only they need.

#include <cstddef>
#include <cstdint>
#include <span>
#include <string>

#include "plcemu/config/config.hpp"
#include "plcemu/daemon/plc.hpp"
#include "plcemu/engine/engine.hpp"
#include "plcemu/image/image.hpp"
#include "plcemu/plant/plant.hpp"
#include "support/wire.hpp"

namespace plcemu::testing {

/// A daemon::Plc of config `yaml`, read as file `file` (which errors name). With `storage` the
/// image lives there, as a state file's does, and `start` says what it holds.
struct PlcRig {
    PlcRig(const std::string& yaml,
           const std::string& file,
           std::span<std::byte> storage = {},
           daemon::Start start = daemon::Start::Retained)
        : plc(config::parse_config(yaml, file), storage, start) {}

    /// Runs `n` scans, the calendar at `calendar`.
    void scan(std::uint64_t n = 1, const engine::Calendar& calendar = {}) {
        plc.engine().run_scans(n, calendar);
    }

    /// A bit.
    bool bit(image::Area a, std::uint32_t i) { return plc.image().bit(a, i); }
    /// Sets a bit.
    void set(image::Area a, std::uint32_t i, bool v) { plc.image().set_bit(a, i, v); }
    /// A word.
    std::uint16_t word(image::Area a, std::uint32_t i) { return plc.image().word(a, i); }
    /// Sets a word.
    void set_word(image::Area a, std::uint32_t i, std::uint16_t v) {
        plc.image().set_word(a, i, v);
    }

    /// R`i`, raw.
    std::uint16_t r(std::uint32_t i) { return word(image::Area::R, i); }
    /// Sets R`i` to `v` (a negative value as its two's complement).
    void set_r(std::uint32_t i, int v) {
        set_word(image::Area::R, i, static_cast<std::uint16_t>(v));
    }
    /// Sets R`at` and the `n` - 1 registers after it to `v`.
    void set_block(std::uint32_t at, int v, int n) {
        for (int k = 0; k < n; ++k) set_r(at + static_cast<std::uint32_t>(k), v);
    }
    /// D`i`, raw.
    std::uint16_t d(std::uint32_t i) { return word(image::Area::D, i); }
    bool y(std::uint32_t i) { return bit(image::Area::Y, i); }
    bool m(std::uint32_t i) { return bit(image::Area::M, i); }
    void set_m(std::uint32_t i, bool v) { set(image::Area::M, i, v); }

    /// Breaks (or mends) the sensor of plant channel `channel`; its other faults are cleared.
    void sensor_broken(int channel, bool broken) {
        plant::Faults f;
        f.sensor_broken = broken;
        plc.plant().set_faults(channel, f);
    }

    daemon::Plc plc;
};

/// A PlcRig with a Wire on its Modbus side (libmodbus as the oracle of every reply).
struct WiredPlcRig : PlcRig {
    WiredPlcRig(const std::string& yaml, const std::string& file)
        : PlcRig(yaml, file) {}

    Wire wire{plc};
};

}  // namespace plcemu::testing
