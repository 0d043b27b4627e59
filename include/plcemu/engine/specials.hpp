#pragma once
// The special relays and registers a PLC family keeps each scan (clocks, first-scan pulse, scan
// time, calendar, station): the engine calls its family's Specials at fixed points of the scan
// and knows nothing of which devices they are.

#include <chrono>
#include <cstdint>
#include <optional>

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
    /// A reload of a running PLC, which a family may treat as its STOP→RUN (the image keeps
    /// its values; no power-up).
    virtual void reload(image::Image& /*image*/) noexcept {}
    /// At the start of each scan, before inputs and the program: clocks, first-scan pulse.
    virtual void scan_start(const ScanContext& ctx) noexcept = 0;
    /// At the end of each scan: scan time, calendar, and the station register showing
    /// `station`, the one in force. Returns the station a master asked for in that register
    /// during the scan when it differs from `station`, or nothing; the scan never grants it.
    virtual std::optional<std::uint8_t> scan_end(const ScanContext& ctx,
                                                 const Calendar& calendar,
                                                 std::uint8_t station) noexcept = 0;
    /// The engine's owner granted `station` (Engine::set_station): a family that keeps the
    /// station in a register shows it there.
    virtual void station_changed(image::Image& /*image*/, std::uint8_t /*station*/) noexcept {}
    /// The PLC entered RUN (true) or STOP: a family shows it in its status devices at once (the
    /// scan keeps them so through ScanContext::running).
    virtual void run_changed(image::Image& /*image*/, bool /*running*/) noexcept {}
};

/// A clock relay: a square wave of the simulated clock, ON for the first half of each `period`.
/// A clock whose half period is shorter than the scan would alias to a constant when sampled at
/// each scan start (a 10 ms clock with a 10 ms scan), so it toggles every scan instead: the
/// fastest wave a program or a master can see.
bool square_wave(const ScanContext& ctx, std::chrono::nanoseconds period) noexcept;

/// Writes `calendar` to seven consecutive words: second, minute, hour, day, month, year (two
/// digits), weekday (0 = Sunday), the order of both the FBs R4128–R4134 and the VB D9013–D9019
/// (docs/profile-fbs.md, docs/profile-vb.md).
void write_calendar(std::uint16_t* seven_words, const Calendar& calendar) noexcept;

/// What write_calendar puts in each of its seven words, for the tag export.
inline constexpr const char* kCalendarWords[7] = {
    "second", "minute", "hour", "day", "month", "year (two digits)", "weekday (0 Sunday)"};

/// The current, minimum and maximum scan time: the simulated interval between scan starts
/// (deterministic, whatever the host's load), counted in whole `unit`s and held to 0–65535.
/// A family decides where the three words go.
struct ScanTimes {
    explicit ScanTimes(std::chrono::nanoseconds per) noexcept
        : unit(per) {}
    /// Forgets the minimum and maximum (at power-up).
    void reset() noexcept {
        min = 0xFFFF;
        max = 0;
    }
    /// Takes this scan's interval, `ctx.dt`.
    void update(const ScanContext& ctx) noexcept;

    std::chrono::nanoseconds unit;  ///< 1 ms on an FBs, 0.1 ms on a VB
    std::uint16_t current = 0;      ///< the last scan's time
    std::uint16_t min = 0xFFFF;     ///< the shortest since power-up
    std::uint16_t max = 0;          ///< the longest since power-up
};

/// A family without special devices (tests of the engine alone).
class NoSpecials final : public Specials {
public:
    void power_up(image::Image& /*image*/, std::uint8_t /*station*/) noexcept override {}
    void scan_start(const ScanContext& /*ctx*/) noexcept override {}
    std::optional<std::uint8_t> scan_end(const ScanContext& /*ctx*/,
                                         const Calendar& /*calendar*/,
                                         std::uint8_t /*station*/) noexcept override {
        return std::nullopt;
    }
};

}  // namespace plcemu::engine
