#include "profiles/vb/specials.hpp"

#include <chrono>
#include <string>

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

    void run_changed(image::Image& image, bool running) noexcept override {
        image.set_bit(Area::M, sp::kRun, running);
    }

    void scan_start(const engine::ScanContext& ctx) noexcept override {
        using std::chrono::milliseconds;
        using std::chrono::minutes;
        using std::chrono::seconds;
        image::Image& img = ctx.image;
        img.set_bit(Area::M, sp::kRun, ctx.running);
        img.set_bit(Area::M, sp::kAlwaysOff, false);
        img.set_bit(Area::M, sp::kFirstScan, ctx.first_scan);
        img.set_bit(Area::M, sp::kAfterFirst, !ctx.first_scan);
        img.set_bit(Area::M, sp::kClock10ms, engine::square_wave(ctx, milliseconds(10)));
        img.set_bit(Area::M, sp::kClock100ms, engine::square_wave(ctx, milliseconds(100)));
        img.set_bit(Area::M, sp::kClock1s, engine::square_wave(ctx, seconds(1)));
        img.set_bit(Area::M, sp::kClock1min, engine::square_wave(ctx, minutes(1)));
    }

    // The VB has no station register: no master asks for another station.
    std::optional<std::uint8_t> scan_end(const engine::ScanContext& ctx,
                                         const engine::Calendar& c,
                                         std::uint8_t /*station*/) noexcept override {
        auto* d = ctx.image.words(Area::D);
        engine::write_calendar(d + sp::kCalendar, c);

        // Scan time in 0.1 ms (scan_ms × 10 while the engine keeps its period): D9010 current,
        // D9011 minimum, D9012 maximum (docs/profile-vb.md).
        scan_times_.update(ctx);
        d[sp::kScanTime] = scan_times_.current;
        d[sp::kScanTime + 1] = scan_times_.min;
        d[sp::kScanTime + 2] = scan_times_.max;
        return std::nullopt;
    }

private:
    engine::ScanTimes scan_times_{std::chrono::microseconds(100)};
};

}  // namespace

engine::Tags special_tags() {
    using engine::Number;
    engine::Tags t{
        {{Area::M, sp::kRun, 1}, "special relay: RUN monitor, always ON"},
        {{Area::M, sp::kAlwaysOff, 1}, "special relay: always OFF"},
        {{Area::M, sp::kFirstScan, 1}, "special relay: initial pulse, ON in the first scan"},
        {{Area::M, sp::kAfterFirst, 1}, "special relay: OFF in the first scan, then ON"},
        {{Area::M, sp::kClock10ms, 1}, "special relay: 10 ms clock"},
        {{Area::M, sp::kClock100ms, 1}, "special relay: 100 ms clock"},
        {{Area::M, sp::kClock1s, 1}, "special relay: 1 s clock"},
        {{Area::M, sp::kClock1min, 1}, "special relay: 1 min clock"},
        {{Area::M, sp::kOperationError, 1}, "special relay: operation error"},
        {{Area::M, sp::kMbusPass, 1}, "special relay: MBUS pass complete, ON for one scan"},
        {{Area::D, sp::kScanTime, 1}, "special register: scan time, 0.1 ms", Number::Unsigned},
        {{Area::D, sp::kScanTime + 1, 1},
         "special register: shortest scan time, 0.1 ms",
         Number::Unsigned},
        {{Area::D, sp::kScanTime + 2, 1},
         "special register: longest scan time, 0.1 ms",
         Number::Unsigned},
        {{Area::D, sp::kErrorCode, 1}, "special register: operation error code", Number::Unsigned},
        {{Area::D, sp::kErrorEntry, 1},
         "special register: program entry (1-based) of the operation error",
         Number::Unsigned},
        {{Area::D, sp::kMbusTimeout, 1},
         "special register: MBUS slave time-out, 10 ms (0: 100 ms)",
         Number::Unsigned},
    };
    for (std::uint32_t i = 0; i < 7; ++i) {
        t.push_back({{Area::D, sp::kCalendar + i, 1},
                     std::string("special register: calendar ") + engine::kCalendarWords[i],
                     Number::Unsigned});
    }
    // M9200-M9234: the direction of C200-C234 (docs/profile-vb.md).
    for (std::uint32_t i = 0; i < sp::kCountDownRelays; ++i) {
        t.push_back({{Area::M, sp::kCountDown + i, 1},
                     "special relay: C" + std::to_string(200 + i) + " counts down when ON"});
    }
    return t;
}

std::unique_ptr<engine::Specials> make_specials() { return std::make_unique<VbSpecials>(); }

}  // namespace plcemu::profiles::vb
