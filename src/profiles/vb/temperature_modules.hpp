#pragma once
// The VB temperature modules VB-8T, VB-4T, VB-4PT and VB-2PT as the program sees them through
// FROM/TO: a buffer memory per module with the channels' modes, a ready status and the readings
// in 0.1 °C (VB manual FNC88 and FNC92 examples; docs/profile-vb.md, "Temperature modules").

#include <array>
#include <cstdint>
#include <vector>

#include "plcemu/engine/engine.hpp"
#include "plcemu/engine/modules.hpp"
#include "plcemu/engine/sensors.hpp"
#include "profiles/vb/modules_config.hpp"

namespace plcemu::profiles::vb {

/// Buffer-memory words (CR#) of each module.
namespace cr {
inline constexpr int kWords = 64;                  ///< CR#0–CR#63
inline constexpr int kMode = 0;                    ///< CR#0…: mode of channel 1…
inline constexpr int kStatus = 20;                 ///< CR#20: status (the FNC92 example reads it)
inline constexpr int kStatusAlt = 29;              ///< CR#29: status (the FNC88 example reads it)
inline constexpr int kReadings = 32;               ///< CR#32…: reading of channel 1…, 0.1 °C
inline constexpr std::uint16_t kReady = 1u << 14;  ///< status b14: the module is ready
inline constexpr std::uint16_t kBroken = 32767;    ///< reading of a broken or out-of-range input
}  // namespace cr

/// The modules of a config, measuring plant channels numbered across modules in bus order.
class TemperatureModules final : public engine::Subsystem, public engine::ModuleBus {
public:
    /// `sensors` (the plant, or a fake) must outlive this object.
    TemperatureModules(const std::vector<ModuleConfig>& modules, engine::SensorSource& sensors);

    /// Refreshes the status words and converts every enabled channel.
    void inputs(engine::ScanContext& ctx) noexcept override;

    bool read(int module, int word, std::uint16_t& out) noexcept override;
    bool write(int module, int word, std::uint16_t value) noexcept override;

private:
    struct Module {
        ModuleConfig config;
        int first_channel = 0;  // plant channel of its CH1
        std::array<std::uint16_t, cr::kWords> buffer{};
    };

    std::uint16_t reading(const Module& m, int channel) noexcept;
    std::uint16_t* at(int module, int word) noexcept;  // null: no such word

    std::vector<Module> modules_;
    engine::SensorSource& sensors_;
};

}  // namespace plcemu::profiles::vb
