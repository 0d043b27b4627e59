#pragma once
// One channel of FNC92 TPID: the control law, the overshoot repression, manual mode with its
// bumpless return and the channel's relay auto-tuning (VB manual FNC92, "Temperature PID
// Control"; docs/profile-vb.md, "FNC92 TPID"). It knows nothing of registers: the instruction
// reads the blocks, holds each value to its range and hands them in.

#include <cstdint>

#include "plcemu/engine/engine.hpp"
#include "profiles/vb/relay_tuning.hpp"

namespace plcemu::profiles::vb::tpid {

/// The analog output's full scale: 1000 × 0.1 % (VB manual FNC92, S3+10m).
inline constexpr int kFullScale = 1000;

/// One channel's settings at this scan, already held to their ranges.
struct Settings {
    int kp = 1;              ///< S4+6m, × 0.01 (output 0.1 % per PV unit), ≥ 1
    int ti = 0;              ///< S4+6m+1, × 100 ms; 0 = no integral action
    int td = 0;              ///< S4+6m+2, × 10 ms; 0 = no derivative action
    int r = 0;               ///< S4+6m+3, overshoot repression [PV units]; 0 = none
    double gain_factor = 1;  ///< sensitivity (S3+1): scales Kp down
    double time_factor = 1;  ///< sensitivity (S3+1): scales TI up
    bool forward = false;    ///< S3+2 bit: cooling (PV above SV needs output)
    bool manual = false;     ///< S3+3 bit
    bool tune = false;       ///< S3+4 bit: auto-tuning asked for
    int manual_value = 0;    ///< S3+10m held to 0–1000 (the user's value in manual mode)
};

/// What a control-cycle boundary decided about auto-tuning.
enum class Tuning : std::uint8_t {
    None,    ///< nothing ended
    Done,    ///< the experiment measured its cycle: `gains` go into S4, the AT bit is cleared
    Failed,  ///< the PV did not move (a ≤ 0): the AT bit is cleared, S4 kept, error 6750
};

/// The decision of one control-cycle boundary.
struct Cycle {
    int output = 0;             ///< 0–1000 for the coming cycle
    bool write_output = false;  ///< the instruction stores it in S3+10m (not in manual)
    Tuning tuning = Tuning::None;
    TunedGains gains;  ///< with Tuning::Done
};

/// One channel's state from one scan to the next.
class Loop {
public:
    /// The channel starts (EN rising, or n grew to include it): no integral, and a start-up
    /// phase when it starts in auto.
    void start(const Settings& s) noexcept;
    /// Every execution: mode changes, the end of the start-up phase, the integral over `dt_s`,
    /// the amplitude of an auto-tuning cycle.
    void scan(const Settings& s, int sv, int pv, double dt_s) noexcept;
    /// At a control-cycle boundary, after scan(): the output of the coming cycle. `cycle_s` is
    /// the length of the cycle that just ended.
    Cycle boundary(
        const Settings& s, int sv, int pv, engine::Duration now, double cycle_s) noexcept;
    /// True while the channel runs its relay experiment.
    bool tuning() const noexcept { return tuning_; }
    /// The output latched for the current cycle, 0–1000.
    int output() const noexcept { return output_; }
    /// The integral term, 0–1000 (for tests and the docs' figures).
    double integral() const noexcept { return integral_; }
    /// True while the start-up phase holds the integral at 0.
    bool repressing() const noexcept { return armed_; }

private:
    /// From a held output `value`: the integral that makes the next solution continue it.
    void resume(const Settings& s, double e, double value) noexcept;
    int solve(const Settings& s, double e, int pv, double cycle_s) noexcept;

    double integral_ = 0;   // Σ term, output units
    bool armed_ = false;    // start-up phase: integral held at 0
    bool moved_ = false;    // PV moved towards SV at an earlier boundary of the start-up phase
    bool manual_ = false;   // mode at the previous execution
    bool have_pv_ = false;  // pv_prev_ and e_prev_ hold a previous boundary's values
    int pv_prev_ = 0;       // PV at the previous boundary
    double e_prev_ = 0;     // |E| at the previous boundary
    bool tuning_ = false;
    RelayExperiment relay_;
    int output_ = 0;
};

}  // namespace plcemu::profiles::vb::tpid
