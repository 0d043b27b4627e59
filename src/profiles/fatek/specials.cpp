#include "profiles/fatek/specials.hpp"

#include <chrono>
#include <string>
#include <utility>

#include "plcemu/engine/engine.hpp"
#include "profiles/fatek/special_registers.hpp"

namespace plcemu::profiles::fatek {

namespace {

using image::Area;
namespace sp = special;

class FatekSpecials final : public engine::Specials {
public:
    FatekSpecials(std::uint16_t model_code, std::vector<PowerUpValue> power_up)
        : model_code_(model_code),
          power_up_(std::move(power_up)) {}

    void power_up(image::Image& image, std::uint8_t station) noexcept override {
        auto* r = image.words(Area::R);
        r[sp::kPowerUps] = static_cast<std::uint16_t>(r[sp::kPowerUps] + 1);
        // The family's temperature registers take their defaults at every start.
        for (const auto& [reg, value] : power_up_) r[reg] = value;
        r[sp::kCpuStatus] = 0;
        r[sp::kStation] = station;
        r[sp::kModelCode] = model_code_;
        scan_times_.reset();
    }

    void run_changed(image::Image& image, bool running) noexcept override {
        image.set_bit(Area::M, sp::kRun, running);
    }

    void scan_start(const engine::ScanContext& ctx) noexcept override {
        using std::chrono::milliseconds;
        using std::chrono::seconds;
        image::Image& img = ctx.image;
        img.set_bit(Area::M, sp::kClock10ms, engine::square_wave(ctx, milliseconds(10)));
        img.set_bit(Area::M, sp::kClock100ms, engine::square_wave(ctx, milliseconds(100)));
        img.set_bit(Area::M, sp::kClock1s, engine::square_wave(ctx, seconds(1)));
        img.set_bit(Area::M, sp::kClock60s, engine::square_wave(ctx, seconds(60)));
        img.set_bit(Area::M, sp::kFirstScan, ctx.first_scan);
        img.set_bit(Area::M, sp::kRun, ctx.running);
    }

    std::optional<std::uint8_t> scan_end(const engine::ScanContext& ctx,
                                         const engine::Calendar& c,
                                         std::uint8_t station) noexcept override {
        auto* r = ctx.image.words(Area::R);
        // R4055: a master sets the station by writing 55h in the high byte (FBs manual,
        // R4055; docs/profile-fbs.md, "Modbus map"). The request is reported, and the register
        // shows the station in force until the daemon grants it (station_changed): a station
        // another unit on the PLC's listeners answers is refused (docs/configuration.md,
        // "Sharing a listener").
        const std::uint16_t st = r[sp::kStation];
        const auto wanted = static_cast<std::uint8_t>(st & 0xFF);
        std::optional<std::uint8_t> request;
        if ((st >> 8) == 0x55 && wanted >= 1 && wanted <= 254 && wanted != station) {
            request = wanted;
        }
        r[sp::kStation] = station;
        r[sp::kCpuStatus] = 0;
        r[sp::kModelCode] = model_code_;

        engine::write_calendar(r + sp::kCalendar, c);

        // Scan time in ms (equal to scan_ms while the engine keeps its period): R4136 current,
        // R4137 maximum, R4138 minimum (docs/profile-fbs.md).
        scan_times_.update(ctx);
        r[sp::kScanTime] = scan_times_.current;
        r[sp::kScanTime + 1] = scan_times_.max;
        r[sp::kScanTime + 2] = scan_times_.min;
        return request;
    }

    void station_changed(image::Image& image, std::uint8_t station) noexcept override {
        image.words(Area::R)[sp::kStation] = station;
    }

private:
    std::uint16_t model_code_;
    std::vector<PowerUpValue> power_up_;
    engine::ScanTimes scan_times_{std::chrono::milliseconds(1)};
};

}  // namespace

std::unique_ptr<engine::Specials> make_specials(std::uint16_t model_code,
                                                std::vector<PowerUpValue> power_up) {
    return std::make_unique<FatekSpecials>(model_code, std::move(power_up));
}

engine::Tags special_tags() {
    using engine::Number;
    engine::Tags t{
        {{Area::M, sp::kClock10ms, 1}, "special relay: 0.01 s clock"},
        {{Area::M, sp::kClock100ms, 1}, "special relay: 0.1 s clock"},
        {{Area::M, sp::kClock1s, 1}, "special relay: 1 s clock"},
        {{Area::M, sp::kClock60s, 1}, "special relay: 60 s clock"},
        {{Area::M, sp::kFirstScan, 1}, "special relay: first-scan pulse"},
        {{Area::M, sp::kRun, 1}, "special relay: RUN"},
        {{Area::R, sp::kCpuStatus, 1},
         "special register: CPU status (0 running normally)",
         Number::Unsigned},
        {{Area::R, sp::kStation, 1},
         "special register: station (write 55h in the high byte to set it)",
         Number::Unsigned},
        {{Area::R, sp::kPowerUps, 1}, "special register: power-up count", Number::Unsigned},
        {{Area::R, sp::kScanTime, 1}, "special register: scan time, ms", Number::Unsigned},
        {{Area::R, sp::kScanTime + 1, 1},
         "special register: longest scan time, ms",
         Number::Unsigned},
        {{Area::R, sp::kScanTime + 2, 1},
         "special register: shortest scan time, ms",
         Number::Unsigned},
        {{Area::R, sp::kModelCode, 1}, "special register: model code", Number::Unsigned},
    };
    for (std::uint32_t i = 0; i < 7; ++i) {
        t.push_back({{Area::R, sp::kCalendar + i, 1},
                     std::string("special register: calendar ") + engine::kCalendarWords[i],
                     Number::Unsigned});
    }
    return t;
}

}  // namespace plcemu::profiles::fatek
