#pragma once
// The special relays and registers a PLC family keeps each scan (clocks, first-scan pulse, scan
// time, calendar, station): the engine calls its family's Specials at fixed points of the scan
// and knows nothing of which devices they are.

#include <chrono>
#include <cstdint>

namespace plcemu::image {
class Image;
}

namespace plcemu::engine {

struct ScanContext;
struct Calendar;

/// One family's special devices.
class Specials {
public:
    virtual ~Specials() = default;
    /// Power-up values, after the image holds its retained values and before any scan.
    /// `station` is the configured station; a family may keep it in a register.
    virtual void power_up(image::Image& image, std::uint8_t station) noexcept = 0;
    /// At the start of each scan, before inputs and the program: clocks, first-scan pulse.
    virtual void scan_start(const ScanContext& ctx) noexcept = 0;
    /// At the end of each scan: scan time, calendar, and the station a master may have changed
    /// in a register (written back to `station`).
    virtual void scan_end(const ScanContext& ctx,
                          const Calendar& calendar,
                          std::uint8_t& station) noexcept = 0;
};

/// A clock relay: a square wave of the simulated clock, ON for the first half of each `period`.
/// A clock whose half period is shorter than the scan would alias to a constant when sampled at
/// each scan start (a 10 ms clock with a 10 ms scan), so it toggles every scan instead: the
/// fastest wave a program or a master can see.
bool square_wave(const ScanContext& ctx, std::chrono::nanoseconds period) noexcept;

/// A family without special devices (tests of the engine alone).
class NoSpecials final : public Specials {
public:
    void power_up(image::Image& /*image*/, std::uint8_t /*station*/) noexcept override {}
    void scan_start(const ScanContext& /*ctx*/) noexcept override {}
    void scan_end(const ScanContext& /*ctx*/,
                  const Calendar& /*calendar*/,
                  std::uint8_t& /*station*/) noexcept override {}
};

}  // namespace plcemu::engine
