#pragma once
// The PID temperature loop FATEK's temperature-control instructions share: FBs FUN86 TPCTL
// (FBs manual §21.7) and the FB's FUN73 TSTC and FUN86 TPCTL (FB manual FUN73/FUN86). The
// positional PID law, the in-zone band, the over-temperature and heater-open warnings, the PWM
// outputs and the R4005 timing codes are one mechanism; the families differ only in the figures
// LoopRules holds (docs/profile-fbs.md "FUN86 TPCTL", docs/profile-fb.md "FUN73 TSTC").

#include <array>
#include <chrono>
#include <cstdint>
#include <optional>
#include <vector>

#include "plcemu/engine/engine.hpp"
#include "plcemu/image/image.hpp"

namespace plcemu::profiles::fatek {

/// Words of a loop's status block (in-zone, warnings, timing, the warnings' causes).
inline constexpr std::uint32_t kLoopStatusWords = 9;
/// Points one loop can control.
inline constexpr int kLoopMaxPoints = 32;
/// Consecutive scans at or above R4008 before the over-temperature warning.
inline constexpr int kOverTemperatureScans = 10;

/// Gains a point whose PR is 0 gets on the first execution.
struct LoopGains {
    std::uint16_t kc = 0;  ///< Kc
    std::uint16_t ki = 0;  ///< integral rate, 0.01 repeats/min
    std::uint16_t td = 0;  ///< derivative time, 0.01 min
};

/// What one family's loop is made of.
struct LoopRules {
    int full_scale = 0;               ///< the PID output OR+i runs 0…full_scale
    int gain_ceiling = 0;             ///< Kc, Ki/Ti and Td above it count as it
    int min_heater_open_seconds = 0;  ///< R4007 below it is taken as it
    int min_over_temperature = 0;     ///< R4008 below it is taken as it
    std::vector<int> timing_seconds;  ///< R4005 byte code → seconds; codes past the end: last
    bool broken_counts_over = false;  ///< a broken point's reading can raise over-temperature
    bool signed_offset = false;       ///< Os is signed (< 0: never in zone), else unsigned
};

/// The devices of one loop: point i is temperature point first + i.
struct LoopBlocks {
    image::Device y;                        ///< PWM outputs Y+i
    image::Device sv, os, pr, ir, dr, out;  ///< per-point blocks
    image::Device status;                   ///< kLoopStatusWords words
    int first = 0;                          ///< first point (Sn, Sh)
    int points = 0;                         ///< points controlled
};

/// One point's process value this scan.
struct LoopInput {
    int pv = 0;           ///< reading, in the unit of SV and Os
    bool broken = false;  ///< no temperature: the output is forced off
};

/// One instruction's loop.
class TemperatureLoop {
public:
    /// `gain` multiplies the error before the PID (the FB's 4095/FS; 1 in the FBs);
    /// `integrate_in_band_only` is the FBs Md 0; `over_scale` multiplies R4008 (10 when the
    /// readings are in 0.1° and R4008 in whole degrees).
    TemperatureLoop(const LoopRules* rules,
                    const LoopBlocks& blocks,
                    double gain,
                    bool integrate_in_band_only,
                    int over_scale);

    /// At EN's rise: R4005 is read only here, so a change while EN = 1 waits for the next rise.
    void latch_timing(const image::Image& img);
    /// "At the first execution": `defaults` for every point whose PR is still 0. Once per
    /// power-up; later calls do nothing.
    void first_execution(image::Image& img, const LoopGains& defaults);
    /// Not running: Y off, OR 0, status 0, PID state reset.
    void stop(image::Image& img);
    /// One scan of PID, zone, warnings and PWM, heating or (not `heating`) cooling. `inputs[i]`
    /// is point i's PV. Writes Y, OR and the status block; returns the alarm (an enabled point
    /// out of zone, or any warning).
    bool run(engine::ScanContext& ctx,
             bool heating,
             const std::array<LoopInput, kLoopMaxPoints>& inputs);

    /// A new error scale (the FB's full scale follows R4009's unit).
    void set_gain(double gain) noexcept { gain_ = gain; }
    /// A new R4008 multiplier (the FB's RTD readings are in 0.1°, R4008 in whole degrees).
    void set_over_scale(int over_scale) noexcept { over_scale_ = over_scale; }
    /// The timing in effect, as the status block's fifth word shows it.
    std::uint16_t timing_word() const;
    const LoopBlocks& blocks() const noexcept { return b_; }

private:
    struct Point {
        double integral = 0.0;                       // Σ term, output counts
        int pv_prev = 0;                             // PV when the loop was last solved
        bool solved = false;                         // pv_prev is valid
        std::uint16_t output = 0;                    // OR value
        engine::Duration on{0};                      // PWM on-time latched for the cycle
        int over_scans = 0;                          // consecutive scans with PV ≥ R4008
        bool over = false;                           // over-temperature warning
        std::optional<engine::Duration> high_since;  // output high while out of zone, since
        bool open = false;                           // heater-open warning

        void reset() { *this = Point{}; }
        void reset_control();
    };

    std::chrono::seconds timing(unsigned code) const;
    std::uint16_t word(const image::Image& img, const image::Device& base, int i) const;
    void set_word(image::Image& img, const image::Device& base, int i, std::uint16_t v) const;
    void set_y(image::Image& img, int i, bool v) const;
    bool pid_enabled(const image::Image& img, int point) const;
    void solve_point(const image::Image& img, int i, Point& p, int pv, int sv) const;

    const LoopRules* rules_;
    LoopBlocks b_;
    double gain_;
    bool band_only_;
    int over_scale_;
    std::array<Point, kLoopMaxPoints> points_{};
    bool defaults_given_ = false;
    bool running_ = false;
    bool heating_ = true;
    bool cycle_due_ = false;
    std::chrono::seconds ts_{0};
    std::chrono::seconds pwm_{0};
    engine::Duration next_solve_{0};
    engine::Duration cycle_start_{0};
};

}  // namespace plcemu::profiles::fatek
