#pragma once
// Drives the engine from real time: one scan per period at absolute deadlines, simulated time
// running `time_scale` times faster than real time. The engine itself never reads a clock; the
// deadlines are a ScanSchedule's, the clock read and the scans run here.

#include <asio.hpp>
#include <array>
#include <chrono>
#include <cstdint>
#include <functional>
#include <memory>
#include <string>

#include "plcemu/engine/engine.hpp"
#include "plcemu/engine/loop_history.hpp"
#include "plcemu/engine/time_control.hpp"
#include "scan_schedule.hpp"
#include "scan_timer.hpp"
#include "step_rounds.hpp"

namespace plcemu::daemon {

/// Lateness of scan starts against their real-time deadlines.
struct LatenessStats {
    /// Histogram resolution; the last bucket holds everything from 10 ms up.
    static constexpr std::chrono::microseconds kBucket{10};
    static constexpr std::size_t kBuckets = 1001;

    std::uint64_t scans = 0;                          ///< scans run by the driver
    std::chrono::nanoseconds max{0};                  ///< worst lateness
    std::uint64_t over_1ms = 0;                       ///< scans started more than 1 ms late
    std::array<std::uint32_t, kBuckets> histogram{};  ///< scans per 10 µs of lateness
    std::chrono::nanoseconds sum{0};                  ///< all lateness together

    /// Records one scan start `late` after its deadline.
    void record(std::chrono::nanoseconds late) noexcept;
    /// The lateness that `fraction` (e.g. 0.99) of the scans did not exceed, to 10 µs.
    std::chrono::microseconds percentile(double fraction) const noexcept;
    /// The same scans in the metrics' buckets (each bound of DurationHistogram is a multiple of
    /// 10 µs: a bucket counts the scans below its bound and not below the previous one).
    engine::DurationHistogram coarse() const noexcept;
};

/// The real-time scan loop of one PLC, woken by the process's one ScanTimer; its queued steps run
/// in the process's StepRounds.
class ScanDriver final : public engine::TimeControl, private Scheduled, private Stepper {
public:
    using Clock = std::chrono::steady_clock;

    /// `prefix` starts its log lines: "plcs[1] (kiln): ", or "" for the one PLC of a plain
    /// config.
    ScanDriver(ScanTimer& timer,
               StepRounds& rounds,
               engine::Engine& engine,
               double time_scale,
               std::string prefix = {});
    ~ScanDriver() override;
    ScanDriver(const ScanDriver&) = delete;
    ScanDriver& operator=(const ScanDriver&) = delete;

    /// Starts scanning now.
    void start() { start_at(Clock::now()); }
    /// Starts scanning: the first scan at `first` (real time), then every scan period.
    void start_at(Clock::time_point first);
    /// Stops scanning.
    void stop();
    /// Changes the time scale without a jump in simulated time.
    void set_time_scale(double scale) noexcept override;
    /// The time scale.
    double time_scale() const noexcept override { return schedule_.time_scale(); }
    /// Freezes (no scans) or resumes.
    void set_frozen(bool frozen) noexcept override;
    /// True while frozen.
    bool frozen() const noexcept override { return schedule_.frozen(); }
    /// Queues `n` scans (meant for a frozen engine); they run in the step rounds, a slice at a
    /// time between other work on the loop, so long steps of many PLCs never starve the clients.
    void step(std::uint64_t n) noexcept override;
    /// Scans queued by step() and not yet run.
    std::uint64_t pending_steps() const noexcept override { return schedule_.pending_steps(); }
    /// Drops the queued scans.
    void cancel_steps() noexcept override;
    /// Simulated time of the last scan.
    engine::Duration simulated_time() const noexcept override { return engine_.now(); }
    /// True while frozen, or while the scans keep their schedule: the last one ran within two
    /// periods (at least 2 s), the next is not overdue by more than two periods (at least
    /// 0.5 s), and the schedule was not skipped ahead twice, the second time within as long
    /// (engine::TimeControl::on_schedule).
    bool on_schedule() const noexcept override;
    std::uint64_t lateness_p99_us() const noexcept override {
        return static_cast<std::uint64_t>(lateness_.percentile(0.99).count());
    }
    std::uint64_t lateness_max_us() const noexcept override {
        return static_cast<std::uint64_t>(
            std::chrono::duration_cast<std::chrono::microseconds>(lateness_.max).count());
    }
    /// Called after every scan, with the real time the scan began.
    void on_scan(std::function<void(Clock::time_point)> f) { on_scan_ = std::move(f); }
    /// Hands every scan to `history` (the console's trends), which must outlive the driver. A
    /// pointer, not an on_scan() function: thousands of PLCs call it 100 times a second each.
    void record_loops(engine::LoopHistory& history) noexcept { history_ = &history; }
    /// Asked, after a scan in which a master asked for another station (R4055), whether the PLC
    /// may have it: true grants it (engine::Engine::set_station). Unset, every request is granted.
    void on_station_request(std::function<bool(std::uint8_t)> f) { grant_ = std::move(f); }
    /// Lateness figures.
    const LatenessStats& lateness() const { return lateness_; }
    std::optional<engine::ScanFigures> scan_figures() const noexcept override {
        return engine::ScanFigures{lateness_.coarse(), duration_};
    }

private:
    void arm();
    Clock::time_point due(Clock::time_point now) override;
    void prefetch(int stage) const noexcept override;
    Clock::time_point tick(Clock::time_point start);
    bool step_once() noexcept override;
    void run_one(engine::Duration sim, Clock::time_point now);
    void update_calendar(Clock::time_point now);

    ScanTimer& timer_;
    ScanTimer::Slot slot_;
    StepRounds& rounds_;
    engine::Engine& engine_;
    ScanSchedule schedule_;
    std::string prefix_;
    bool running_ = false;
    engine::Calendar calendar_{};
    std::time_t calendar_second_ = -1;
    Clock::time_point next_second_{};  // when the wall clock's next second begins (steady time)
    std::function<void(Clock::time_point)> on_scan_;
    engine::LoopHistory* history_ = nullptr;
    std::function<bool(std::uint8_t)> grant_;
    LatenessStats lateness_;
    engine::DurationHistogram duration_;  // how long the scans took
    Clock::time_point last_scan_{};       // real time of the last scan tick() ran (or the start)
    Clock::time_point last_skip_{};       // when the schedule last skipped ahead (never: epoch)
    Clock::time_point previous_skip_{};   // the skip before that
    Clock::duration skipped_{};           // how far behind it was then, for the next lateness
};

}  // namespace plcemu::daemon
