#pragma once
// FBs temperature measurement (FBs manual §21.3): the configuration table at A556h, the
// emulated TC/RTD modules converting their channels one after another, the readings and the
// working registers. Not an instruction: a subsystem that runs before the program each scan.

#include <algorithm>
#include <array>
#include <cstdint>
#include <memory>
#include <optional>
#include <vector>

#include "plcemu/config/config.hpp"
#include "plcemu/engine/engine.hpp"
#include "plcemu/image/area.hpp"
#include "plcemu/engine/sensors.hpp"
#include "plcemu/engine/tags.hpp"
#include "profiles/fbs/temperature_config.hpp"

namespace plcemu::profiles::fbs {

/// Constants of the FBs manual §21.3 and docs/profile-fbs.md, "Temperature measurement".
namespace temperature {
inline constexpr std::uint16_t kValidTable = 0xA556;    ///< SR+0 of a valid table
inline constexpr std::uint16_t kBroken = 32767;         ///< reading of an open (broken) sensor
inline constexpr std::uint8_t kIdle = 0x00;             ///< execute code: idle / invalid table
inline constexpr std::uint8_t kBadModuleCount = 0xFE;   ///< execute code: N = 0 or N > 8
inline constexpr std::uint8_t kTooManyChannels = 0xFF;  ///< execute code: more than 32 channels
inline constexpr std::uint8_t kRunning = 0x56;          ///< execute code: all read, running
inline constexpr int kMaxChannels = 32;                 ///< channels the table may number
inline constexpr int kMaxModules = 8;                   ///< modules the table may list

/// Module name codes, in the manual's order (docs/profile-fbs.md, "Temperature measurement").
enum class Module : std::uint8_t { TC6 = 1, RTD6 = 2, TC16 = 3, RTD16 = 4, TC2 = 5 };

/// Channels of a module name code (0 for an unknown code).
int channels_of(std::uint8_t name_code);
/// Normal conversion time of a module in ms (fast: half), 0 for an unknown code.
int conversion_ms(std::uint8_t name_code);
/// True for the RTD modules.
bool is_rtd(std::uint8_t name_code);
/// Range in °C of a sensor type code on a module; false when the code is not a sensor of that
/// module family.
bool sensor_range(std::uint8_t name_code, std::uint8_t sensor, double& lo_c, double& hi_c);
/// Decodes an R4004-style reference (10000+n = Rn, 20000+n = Dn).
std::optional<image::Device> decode_register(std::uint16_t v);
/// Encodes a word device as an R4004-style reference.
std::uint16_t encode_register(const image::Device& d);
/// Y points of the main unit of the config's model (FBs-24MC: 10, Y0–Y9).
std::uint32_t main_unit_outputs(const config::Config& config);
/// The Y points the declared modules occupy, 8 each after the main unit's (FBs manual §21.3:
/// "each module occupies 1 IR and 8 DO"); nothing when `temperature.modules` is empty.
std::optional<image::Range> module_outputs(const config::Config& config);
}  // namespace temperature

/// How the measurement is set up (from `temperature:` and the model).
struct TemperatureOptions {
    image::Device table{image::Area::R, 5000, false};  ///< SR: start of the configuration table
    std::vector<ModuleConfig> installed;               ///< the expansion chain (empty: as table)
    bool fast = false;                                 ///< "scan rate" fast
    std::uint32_t main_unit_outputs = 10;              ///< Y points of the main unit
};

/// The FBs temperature measurement (FBs manual §21.3), as an engine subsystem.
class TemperatureTable final : public engine::Subsystem {
public:
    /// `sensors` (the plant, or a fake) must outlive this object.
    TemperatureTable(TemperatureOptions options, engine::SensorSource& sensors);

    /// Options from a config (which must have `temperature.table`).
    static TemperatureOptions options_of(const config::Config& config);

    /// Reads the table and the special registers, converts what is due, writes readings and
    /// working registers.
    void inputs(engine::ScanContext& ctx) noexcept override;

    /// The execute code last written (WR+0 high byte).
    std::uint8_t execute_code() const { return code_; }

private:
    struct ModuleState {
        std::uint8_t name = 0;      // table's module name code
        std::uint8_t sensor = 0;    // table's sensor type code
        int channels = 0;           // channels of the module
        int first = 0;              // global number of its first channel
        bool mismatch = false;      // differs from the installed module
        bool sensor_ok = false;     // sensor code valid for the module
        double lo_c = 0, hi_c = 0;  // sensor range
        std::int64_t slot_ns = 0;   // time per channel conversion
        std::int64_t done = 0;      // conversions completed since the restart
        int current = 0;            // module-local channel being converted
    };
    // A channel's samples; whether it was read and whether it is broken are bits of read_ and
    // broken_, so the per-scan status words do not visit every channel's samples.
    struct ChannelState {
        std::array<double, 16> avg{};  // last samples, °C (moving average of up to 16)
        int count = 0;                 // samples held in avg
        int next = 0;                  // ring position
    };

    void restart(const image::Image& img, std::int64_t now) noexcept;
    /// A bit for each of the table's total_ channels.
    std::uint32_t channel_mask() const noexcept {
        return total_ >= 32 ? ~0u : (1u << std::max(total_, 0)) - 1u;
    }
    void convert(engine::ScanContext& ctx, ModuleState& m) noexcept;
    void put(image::Image& img,
             const image::Device& base,
             std::uint32_t offset,
             std::uint16_t v) const noexcept;

    TemperatureOptions opt_;
    engine::SensorSource& sensors_;
    std::array<std::uint16_t, 4 + temperature::kMaxModules> snapshot_{};
    bool have_snapshot_ = false;
    // The table as last read.
    bool marker_ok_ = false;
    std::optional<image::Device> readings_;
    std::optional<image::Device> wr_;
    std::uint16_t n_ = 0;
    int total_ = 0;
    std::uint8_t mismatch_ = 0;
    std::vector<ModuleState> modules_;
    std::array<ChannelState, temperature::kMaxChannels> ch_{};
    static_assert(temperature::kMaxChannels <= 32, "read_ and broken_ hold a bit per channel");
    std::uint32_t read_ = 0;    // channels read at least once since the restart
    std::uint32_t broken_ = 0;  // channels whose abnormal bit is set
    std::int64_t start_ns_ = 0;
    std::uint8_t code_ = temperature::kIdle;
};

/// What the configuration table at `temperature.table` holds, and the readings and working
/// registers it names as `image` holds it (nothing without a table), for the tag export.
engine::Tags temperature_tags(const config::Config& config, const image::Image& image);

/// A TemperatureTable for a config with `temperature.table`, reading from `sensors`.
std::unique_ptr<TemperatureTable> make_temperature_table(const config::Config& config,
                                                         engine::SensorSource& sensors);

}  // namespace plcemu::profiles::fbs
