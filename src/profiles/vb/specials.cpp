#include "profiles/vb/specials.hpp"

#include <algorithm>
#include <chrono>

#include "plcemu/engine/engine.hpp"

namespace plcemu::profiles::vb {

namespace {

using image::Area;
namespace sp = special;

class VbSpecials final : public engine::Specials {
public:
    void power_up(image::Image& image, std::uint8_t /*station*/) noexcept override {
        // FX2N behaviour at STOP→RUN: the error flag and code are cleared (VB manual FNC88,
        // error codes in D9067), the MBUS time-out takes its default (VB manual FNC149, D9129).
        image.set_bit(Area::M, sp::kOperationError, false);
        auto* d = image.words(Area::D);
        d[sp::kErrorCode] = 0;
        d[sp::kErrorEntry] = 0;
        d[sp::kMbusTimeout] = 0;
        scan_min_ = 0xFFFF;
        scan_max_ = 0;
    }

    void scan_start(const engine::ScanContext& ctx) noexcept override {
        using std::chrono::milliseconds;
        using std::chrono::minutes;
        using std::chrono::seconds;
        image::Image& img = ctx.image;
        img.set_bit(Area::M, sp::kRun, true);
        img.set_bit(Area::M, sp::kAlwaysOff, false);
        img.set_bit(Area::M, sp::kFirstScan, ctx.first_scan);
        img.set_bit(Area::M, sp::kAfterFirst, !ctx.first_scan);
        img.set_bit(Area::M, sp::kClock10ms, engine::square_wave(ctx, milliseconds(10)));
        img.set_bit(Area::M, sp::kClock100ms, engine::square_wave(ctx, milliseconds(100)));
        img.set_bit(Area::M, sp::kClock1s, engine::square_wave(ctx, seconds(1)));
        img.set_bit(Area::M, sp::kClock1min, engine::square_wave(ctx, minutes(1)));
    }

    // The VB has no station register: `station` stays as configured.
    void scan_end(const engine::ScanContext& ctx,
                  const engine::Calendar& c,
                  std::uint8_t& /*station*/) noexcept override {
        auto* d = ctx.image.words(Area::D);
        d[sp::kCalendar + 0] = static_cast<std::uint16_t>(c.second);
        d[sp::kCalendar + 1] = static_cast<std::uint16_t>(c.minute);
        d[sp::kCalendar + 2] = static_cast<std::uint16_t>(c.hour);
        d[sp::kCalendar + 3] = static_cast<std::uint16_t>(c.day);
        d[sp::kCalendar + 4] = static_cast<std::uint16_t>(c.month);
        d[sp::kCalendar + 5] = static_cast<std::uint16_t>(c.year % 100);
        d[sp::kCalendar + 6] = static_cast<std::uint16_t>(c.weekday);

        // Scan time in 0.1 ms: the simulated interval between scan starts (deterministic;
        // scan_ms × 10 while the engine keeps its period).
        const auto tenths =
            std::chrono::duration_cast<std::chrono::microseconds>(ctx.dt).count() / 100;
        const auto cur = static_cast<std::uint16_t>(std::clamp<long long>(tenths, 0, 0xFFFF));
        scan_min_ = std::min(scan_min_, cur);
        scan_max_ = std::max(scan_max_, cur);
        d[sp::kScanTime] = cur;
        d[sp::kScanTime + 1] = scan_min_;
        d[sp::kScanTime + 2] = scan_max_;
    }

private:
    std::uint16_t scan_min_ = 0xFFFF;
    std::uint16_t scan_max_ = 0;
};

}  // namespace

std::unique_ptr<engine::Specials> make_specials() { return std::make_unique<VbSpecials>(); }

}  // namespace plcemu::profiles::vb
