#pragma once
// The recent past of a program's control loops, for the trends of the console's loops page
// (docs/console.md, "Loops"): one sample a simulated second of each loop's PV, SV and output,
// the last 10 simulated minutes. Kept only for a PLC whose loops someone has looked at, so that
// a process of thousands of PLCs pays nothing for it; the daemon feeds it after every scan.

#include <cstddef>
#include <cstdint>
#include <vector>

#include "plcemu/engine/engine.hpp"
#include "plcemu/engine/loops.hpp"

namespace plcemu::engine {

/// The loops of a program, as its instructions describe them, in program order.
Loops loops_of(const Engine& engine);

/// One sample of a loop.
struct LoopSample {
    double t = 0;       ///< simulated seconds
    double pv = 0;      ///< in the loop's units; NaN while it has no source
    double sv = 0;      ///< in the loop's units
    double output = 0;  ///< % of full scale, or the raw word for a loop without one
};

/// The last samples of every loop of one PLC's program.
class LoopHistory {
public:
    /// Samples kept per loop, one per simulated second: 10 simulated minutes.
    static constexpr std::size_t kSamples = 600;

    /// Starts keeping samples (from the next scan on); once watched, always watched.
    void watch() noexcept { watched_ = true; }
    /// After a scan of `engine`: takes a sample when a simulated second has passed since the
    /// last. A new program (a reload) or simulated time gone back starts the history over.
    void after_scan(const Engine& engine);
    /// The loops sampled (empty until the first sample).
    std::size_t loops() const { return loops_.size(); }
    /// The samples of loop `i`, oldest first.
    std::vector<LoopSample> samples(std::size_t i) const;

private:
    void restart(const Engine& engine);

    bool watched_ = false;
    const void* program_ = nullptr;  // the program the loops were described from
    std::uint64_t scans_ = 0;        // the engine's scans at the last call
    Loops loops_;
    std::vector<LoopSample> ring_;  // kSamples rows of loops_.size() samples
    std::size_t next_ = 0;          // the row written next
    std::size_t rows_ = 0;          // rows written, at most kSamples
    Duration due_{};                // the simulated time of the next sample
};

}  // namespace plcemu::engine
