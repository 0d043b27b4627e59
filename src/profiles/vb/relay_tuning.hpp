#pragma once
// The relay auto-tuning experiment that FNC88 PID and FNC92 TPID share (VB manual FNC88,
// "Auto-tuning Function": the PLC evaluates Kp, TI and TD "using relay ON/OFF"). The manual
// gives no formulas; the emulator runs the Åström–Hägglund relay experiment and applies the
// Ziegler–Nichols ultimate-cycle rule (docs/profile-vb.md, "Auto-tuning").

#include <cstdint>

#include "plcemu/engine/engine.hpp"

namespace plcemu::profiles::vb {

/// What the experiment measured over its second complete relay cycle.
struct RelayCycle {
    double tau = 0;     ///< period Pu: time between the cycle's two hi→lo changes [s]
    double tau_on = 0;  ///< the part of tau during which the relay was hi [s]
    double a = 0;       ///< peak-to-peak PV over the cycle's observations [PV counts]

    /// The relay's duty over the cycle, tau_on / tau (0 for an empty cycle): the mean output
    /// from which control takes over without a bump.
    double duty() const noexcept { return tau > 0 ? tau_on / tau : 0.0; }
};

/// The PID parameters the Ziegler–Nichols ultimate-cycle rule gives, in the VB's units.
struct TunedGains {
    std::int16_t kp = 1;  ///< 0.6·Ku in % (output counts per 100 PV counts), 1–32767
    std::int16_t ti = 1;  ///< 0.5·Pu in × 100 ms, 1–32767
    std::int16_t td = 0;  ///< 0.125·Pu in × 10 ms, 0–32767
};

/// Ku = 4·(hi − lo)/(π·a), then Kp = 0.6·Ku, TI = 0.5·Pu, TD = 0.125·Pu, each rounded and held
/// to its register's range. `cycle.a` must be > 0.
TunedGains ziegler_nichols(double relay_span, const RelayCycle& cycle) noexcept;

/// One relay experiment. The caller decides when the relay is looked at (each PID sampling,
/// each TPID control-cycle boundary) and which PV values count towards the amplitude.
class RelayExperiment {
public:
    /// Where the experiment stands after a decision.
    enum class State : std::uint8_t {
        Running,   ///< keep switching
        Measured,  ///< the third hi→lo change: `cycle()` holds the second cycle
    };

    /// Starts afresh at `now`.
    void start(engine::Duration now) noexcept;
    /// Takes a PV value into the amplitude of the cycle being measured.
    void observe(double pv) noexcept;
    /// The relay decision at `now`: hi when `demand` (PV on the side of SV that needs output).
    /// Returns Measured at the third hi→lo change, with `cycle()` filled in.
    State decide(engine::Duration now, bool demand) noexcept;
    /// The relay's current position: true = hi.
    bool high() const noexcept { return high_; }
    /// The measured cycle, once decide() has returned Measured.
    const RelayCycle& cycle() const noexcept { return cycle_; }

private:
    bool high_ = false;
    bool decided_ = false;            // no decision taken yet since start()
    int falls_ = 0;                   // hi→lo changes so far
    engine::Duration cycle_start_{};  // the second hi→lo change
    engine::Duration rise_{};         // the lo→hi change inside the measured cycle
    double pv_min_ = 0;
    double pv_max_ = 0;
    double last_pv_ = 0;
    RelayCycle cycle_;
};

}  // namespace plcemu::profiles::vb
