#pragma once
// Drives the engine from real time: one scan per period at absolute deadlines, simulated time
// running `time_scale` times faster than real time. The engine itself never reads a clock.

#include <asio.hpp>
#include <chrono>
#include <cstdint>
#include <functional>

#include "plcemu/engine/engine.hpp"

namespace plcemu::daemon {

/// Lateness of scan starts against their real-time deadlines.
struct LatenessStats {
    std::uint64_t scans = 0;               ///< scans run by the driver
    std::chrono::nanoseconds max{0};       ///< worst lateness
    std::uint64_t over_1ms = 0;            ///< scans started more than 1 ms late
};

/// The real-time scan loop.
class ScanDriver {
public:
    using Clock = std::chrono::steady_clock;

    ScanDriver(asio::io_context& io, engine::Engine& engine, double time_scale);

    /// Starts scanning now.
    void start();
    /// Stops the timer.
    void stop();
    /// Changes the time scale without a jump in simulated time.
    void set_time_scale(double scale);
    /// The time scale.
    double time_scale() const { return scale_; }
    /// Freezes (no scans) or resumes.
    void set_frozen(bool frozen);
    /// True while frozen.
    bool frozen() const { return frozen_; }
    /// Runs `n` scans at once (meant for a frozen engine).
    void step(std::uint64_t n);
    /// Called after every scan (e.g. the systemd watchdog).
    void on_scan(std::function<void()> f) { on_scan_ = std::move(f); }
    /// Lateness figures.
    const LatenessStats& lateness() const { return lateness_; }

private:
    void arm();
    void tick();
    Clock::time_point deadline(engine::Duration sim) const;
    void run_one(engine::Duration sim);
    void rebase(Clock::time_point real_now);

    asio::io_context& io_;
    asio::steady_timer timer_;
    engine::Engine& engine_;
    double scale_;
    bool frozen_ = false;
    bool running_ = false;
    Clock::time_point base_real_{};
    engine::Duration base_sim_{0};
    engine::Duration next_sim_{0};
    engine::Calendar calendar_{};
    std::time_t calendar_second_ = -1;
    std::function<void()> on_scan_;
    LatenessStats lateness_;
};

}  // namespace plcemu::daemon
