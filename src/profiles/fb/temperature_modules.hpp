#pragma once
// The FB temperature modules of the chain as the measuring instructions see them: each sample
// of a point is taken from the plant channel of the same number (FB manual FUN72/FUN73 and
// FUN85; docs/profile-fb.md, "Plant and simulator"). The engine hands them to the instructions
// as its module bus; an FB has no FROM/TO words on them.

#include "plcemu/engine/engine.hpp"
#include "plcemu/engine/modules.hpp"
#include "plcemu/engine/sensors.hpp"

namespace plcemu::profiles::fb {

/// The sensors behind points 0–31.
class TemperatureModules final : public engine::Subsystem, public engine::ModuleBus {
public:
    /// `sensors` (the plant, or a fake) must outlive this object.
    explicit TemperatureModules(engine::SensorSource& sensors)
        : sensors_(sensors) {}

    /// Samples point `point`'s sensor once (the plant channel of the same number).
    engine::SensorSample sense(int point) noexcept { return sensors_.sense(point); }

    /// No buffer words: the FB reads these modules through its instructions only.
    bool read(int /*module*/, int /*word*/, std::uint16_t& /*out*/) noexcept override {
        return false;
    }
    /// No buffer words.
    bool write(int /*module*/, int /*word*/, std::uint16_t /*value*/) noexcept override {
        return false;
    }

    /// The modules of a scan: the instructions that measure find them here.
    static TemperatureModules* of(const engine::ScanContext& ctx) noexcept {
        return dynamic_cast<TemperatureModules*>(ctx.modules);
    }

private:
    engine::SensorSource& sensors_;
};

}  // namespace plcemu::profiles::fb
