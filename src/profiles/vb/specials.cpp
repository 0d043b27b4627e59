#include "profiles/vb/specials.hpp"

#include <chrono>

#include "plcemu/engine/engine.hpp"

namespace plcemu::profiles::vb {

namespace {

using image::Area;
namespace sp = special;

class VbSpecials final : public engine::Specials {
public:
    void power_up(image::Image& image, std::uint8_t /*station*/) noexcept override {
        reload(image);
        // The MBUS time-out takes its default (VB manual FNC149, D9129).
        image.set_word(Area::D, sp::kMbusTimeout, 0);
        scan_times_.reset();
    }

    // FX2N behaviour at STOP→RUN, which a start and a reload both are here: the error flag,
    // code and step are cleared (VB manual FNC88, error codes in D9067).
    void reload(image::Image& image) noexcept override {
        image.set_bit(Area::M, sp::kOperationError, false);
        image.set_word(Area::D, sp::kErrorCode, 0);
        image.set_word(Area::D, sp::kErrorEntry, 0);
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
        engine::write_calendar(d + sp::kCalendar, c);

        // Scan time in 0.1 ms (scan_ms × 10 while the engine keeps its period): D9010 current,
        // D9011 minimum, D9012 maximum (docs/profile-vb.md).
        scan_times_.update(ctx);
        d[sp::kScanTime] = scan_times_.current;
        d[sp::kScanTime + 1] = scan_times_.min;
        d[sp::kScanTime + 2] = scan_times_.max;
    }

private:
    engine::ScanTimes scan_times_{std::chrono::microseconds(100)};
};

}  // namespace

std::unique_ptr<engine::Specials> make_specials() { return std::make_unique<VbSpecials>(); }

}  // namespace plcemu::profiles::vb
