#pragma once
// What the FB PLC knows of each temperature point across instructions: its last samples (for
// the averaging of R4015), whether it has been read since its measuring instruction's EN rose,
// and whether its sensor is broken (FB manual FUN73; docs/profile-fb.md, "Points"). TP4, TSTC
// and TPSNS write it; TSTC and TPCTL read it to gate PID and to turn broken points off.

#include <array>
#include <cstdint>

namespace plcemu::profiles::fb {

/// One temperature point.
class Point {
public:
    /// The most samples R4015 averages.
    static constexpr int kMaxSamples = 16;

    /// Adds a sample (raw count or 0.1 °C), dropping the oldest beyond 16.
    void add(int sample) noexcept;
    /// Forgets the samples (a broken sample empties the average; EN fell).
    void clear_samples() noexcept { count_ = 0; }
    /// Samples kept, at most 16.
    int count() const noexcept { return count_; }
    /// The sum of the last min(n, count()) samples.
    long long sum(int n) const noexcept;
    /// How many samples sum(n) adds.
    int used(int n) const noexcept { return n < count_ ? n : count_; }

    bool read_once = false;  ///< sampled at least once since its instruction's EN rose
    bool broken = false;     ///< the last sample found the sensor broken (installed points only)

    /// Everything back to power-up.
    void reset() noexcept { *this = Point{}; }

private:
    std::array<int, kMaxSamples> samples_{};
    int next_ = 0;   // where the next sample goes
    int count_ = 0;  // samples held
};

/// Points 0–31 of one PLC.
struct Points {
    /// Number of points (TP0–TP31).
    static constexpr int kCount = 32;
    std::array<Point, kCount> at{};  ///< by point number
};

}  // namespace plcemu::profiles::fb
