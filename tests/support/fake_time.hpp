#pragma once
// Test support: the simulator unit's time control without a real-time driver. Steps run the
// engine's scans at once, as the daemon's driver does while frozen, and every call is recorded.

#include <algorithm>
#include <cstdint>
#include <limits>
#include <optional>
#include <vector>

#include "plcemu/engine/engine.hpp"
#include "plcemu/engine/time_control.hpp"

namespace plcemu::testing {

/// A TimeControl over an engine, for unit tests and fuzz harnesses.
class FakeTime final : public engine::TimeControl {
public:
    /// `engine` must outlive this.
    explicit FakeTime(engine::Engine& engine)
        : engine_(engine) {}

    double time_scale() const noexcept override { return scale; }
    void set_time_scale(double s) noexcept override { scale = s; }
    bool frozen() const noexcept override { return frozen_; }
    void set_frozen(bool f) noexcept override {
        frozen_ = f;
        frozen_log.push_back(f);
    }
    void step(std::uint64_t n) noexcept override {
        steps.push_back(n);
        frozen_when_stepped.push_back(frozen_);
        engine_.run_scans(std::min(n, max_step));
    }
    engine::Duration simulated_time() const noexcept override {
        return fixed_time ? *fixed_time : engine_.now();
    }

    double scale = 1.0;            ///< the time scale last set
    std::vector<bool> frozen_log;  ///< every set_frozen, in order
    std::uint64_t pending_steps() const noexcept override { return queued; }
    void cancel_steps() noexcept override {
        queued = 0;
        ++cancels;
    }

    std::uint64_t queued = 0;                    ///< what pending_steps() says
    int cancels = 0;                             ///< cancel_steps() calls
    std::vector<std::uint64_t> steps;            ///< every step request, in order
    std::vector<bool> frozen_when_stepped;       ///< frozen state at each step
    std::optional<engine::Duration> fixed_time;  ///< reported instead of the engine's time
    std::uint64_t max_step =
        std::numeric_limits<std::uint64_t>::max();  ///< scans per step, at most

private:
    engine::Engine& engine_;
    bool frozen_ = false;
};

}  // namespace plcemu::testing
