#pragma once
// The measuring half of FUN72 TP4 and FUN73 TSTC: one FB-2A…4 module's four points read in turn
// over its multiplexing relays, each sample turned into R3968+p and a reading (FB manual
// FUN72/FUN73; docs/profile-fb.md, "TP4 and TSTC: measurement").

#include <cstdint>
#include <memory>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "instructions/operands.hpp"
#include "plcemu/engine/engine.hpp"
#include "plcemu/engine/sensors.hpp"
#include "profiles/fb/points.hpp"

namespace plcemu::profiles::fb {

/// Facts of the measurement that tests and the docs refer to.
namespace cycle {
inline constexpr int kPoints = 4;                   ///< points of one module
inline constexpr std::uint32_t kRelays = 8;         ///< Ym…Ym+7: a pair per point
inline constexpr std::uint32_t kWorkingWords = 8;   ///< TP4's WR (TSTC's first 8)
inline constexpr std::uint32_t kFirstInput = 3840;  ///< AR is an IR: R3840–R3903
inline constexpr std::uint32_t kLastInput = 3903;   ///< last IR
}  // namespace cycle

/// The module operands of a TP4 or TSTC entry, checked.
struct ModuleOperands {
    long long tp = 0;    ///< sensor code (0–5 valid)
    long long pl = 0;    ///< range and polarity (0–3 valid)
    long long sm = 0;    ///< first point (0, 4, …, 28 valid)
    image::Device ym;    ///< first multiplexing relay
    image::Device ar;    ///< the module's multiplexed analog input
    image::Device tr;    ///< first of the 4 readings
    image::Device wr;    ///< working registers
    bool valid = false;  ///< Tp, Pl and Sm in range: the instruction runs
};

/// Binds tp, pl, sm, ym, ar, tr and wr (`wr_words` long). Tp, Pl and Sm take any integer: out
/// of range the instruction reports ERR at run time. With a `temperature.modules` chain the
/// module at Sm must be the one Tp names.
ModuleOperands bind_module(instructions::Operands& ops, std::uint32_t wr_words);

/// What a TP4 or TSTC's measuring half writes — WR (`wr_words`), TR, Ym…Ym+7, AR and the raw
/// readings of its points — each with the operand that names it, for the load checks.
std::vector<std::pair<const char*, engine::Claim>> module_claims(const ModuleOperands& m,
                                                                 std::string_view mnemonic,
                                                                 std::uint32_t wr_words,
                                                                 const std::string& where);

/// The measuring cycle of one module.
class ModuleCycle {
public:
    ModuleCycle(const ModuleOperands& ops, std::shared_ptr<Points> points);

    /// One scan: with `en` the selected point is sampled when its R4014 ms are over and the
    /// next one selected; without, the relays are OFF and the points' flags cleared. Writes the
    /// relays, AR, the readings and WR+0…WR+7. Only for valid operands.
    void run(engine::ScanContext& ctx, bool en) noexcept;
    /// Back to power-up (the first scan after a start).
    void reset() noexcept;
    /// WR+0: bit k set while point Sm+k's sensor is broken.
    std::uint16_t broken_bits() const noexcept;
    /// The operands.
    const ModuleOperands& operands() const noexcept { return ops_; }

private:
    void sample(engine::ScanContext& ctx, int k, const engine::SensorSample& s) noexcept;
    void stop() noexcept;
    void write_status(image::Image& img) const noexcept;
    Point& point(int k) const noexcept;

    ModuleOperands ops_;
    std::shared_ptr<Points> points_;
    bool running_ = false;  // EN was 1 at the last scan
    int selected_ = 0;      // point k (0–3) the relays select
    engine::Duration next_{0};
};

}  // namespace plcemu::profiles::fb
