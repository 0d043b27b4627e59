#pragma once
// Run-time control of simulated time (docs/simulator-and-plant.md, "Simulator-control unit"):
// implemented by the daemon's scan driver, and by a fake in tests.

#include <array>
#include <chrono>
#include <cstdint>
#include <optional>

#include "plcemu/engine/engine.hpp"

namespace plcemu::engine {

/// A histogram of durations with the bounds metrics show (Prometheus' cumulative `le` buckets
/// are made from it).
struct DurationHistogram {
    /// Upper bounds of the buckets, µs; a last bucket holds everything longer.
    static constexpr std::array<std::uint32_t, 9> kBoundsUs{10,   50,   100,  250,  500,
                                                            1000, 2500, 5000, 10000};
    std::array<std::uint64_t, kBoundsUs.size() + 1> buckets{};  ///< counts per bucket
    std::uint64_t count = 0;                                    ///< everything recorded
    std::chrono::nanoseconds sum{0};                            ///< their total

    /// Records one duration.
    void record(std::chrono::nanoseconds d) noexcept {
        std::size_t b = 0;
        while (b < kBoundsUs.size() && d > std::chrono::microseconds(kBoundsUs[b])) ++b;
        ++buckets[b];
        ++count;
        sum += d;
    }
};

/// How the scans of a real-time driver went, for metrics.
struct ScanFigures {
    DurationHistogram lateness;  ///< scan starts after their deadlines
    DurationHistogram duration;  ///< the scans themselves (program, plant, I/O refresh)
};

/// Time scale, freeze and single-stepping of the scan loop.
class TimeControl {
public:
    virtual ~TimeControl() = default;
    /// Simulated seconds per real second.
    virtual double time_scale() const noexcept = 0;
    /// Changes the time scale without a jump in simulated time.
    virtual void set_time_scale(double scale) noexcept = 0;
    /// True while scans are stopped.
    virtual bool frozen() const noexcept = 0;
    /// Stops (true) or resumes (false) the scans.
    virtual void set_frozen(bool frozen) noexcept = 0;
    /// Runs `n` scans, back to back in simulated time (at once, or queued: see pending_steps).
    virtual void step(std::uint64_t n) noexcept = 0;
    /// Scans asked for by step() that have not run yet.
    virtual std::uint64_t pending_steps() const noexcept { return 0; }
    /// Drops the scans asked for by step() that have not run yet.
    virtual void cancel_steps() noexcept {}
    /// Simulated time of the last scan.
    virtual Duration simulated_time() const noexcept = 0;
    /// True while the scans keep their schedule: frozen on purpose, or the last scan ran less
    /// than two scan periods (and at least two seconds) ago and the scans did not fall so far
    /// behind real time, again and again, that the schedule skipped ahead twice, the second
    /// time within as long (a health check asks it).
    virtual bool on_schedule() const noexcept { return true; }
    /// How late scans started against their real-time deadlines: the 99th percentile and the
    /// worst, µs (0 without a real-time driver).
    virtual std::uint64_t lateness_p99_us() const noexcept { return 0; }
    virtual std::uint64_t lateness_max_us() const noexcept { return 0; }
    /// Lateness and duration of the scans run on schedule; none without a real-time driver.
    virtual std::optional<ScanFigures> scan_figures() const noexcept { return std::nullopt; }
};

}  // namespace plcemu::engine
