#include "profiles/fbs/specials.hpp"

#include <chrono>

#include "plcemu/engine/engine.hpp"
#include "profiles/fbs/special_registers.hpp"

namespace plcemu::profiles::fbs {

namespace {

using image::Area;
namespace sp = special;

class FbsSpecials final : public engine::Specials {
public:
    explicit FbsSpecials(std::uint16_t model_code)
        : model_code_(model_code) {}

    void power_up(image::Image& image, std::uint8_t station) noexcept override {
        auto* r = image.words(Area::R);
        r[sp::kPowerUps] = static_cast<std::uint16_t>(r[sp::kPowerUps] + 1);
        // FBs manual §21.7: defaults of R4005–R4008, R4010–R4013 at start.
        r[sp::kPidTiming] = 0x0102;
        r[sp::kHeaterOpenPercent] = 90;
        r[sp::kHeaterOpenSeconds] = 600;
        r[sp::kOverTemperature] = 3500;
        r[sp::kSensorInstalled] = 0xFFFF;
        r[sp::kSensorInstalled + 1] = 0xFFFF;
        r[sp::kPidEnable] = 0xFFFF;
        r[sp::kPidEnable + 1] = 0xFFFF;
        r[sp::kCpuStatus] = 0;
        r[sp::kStation] = station;
        r[sp::kModelCode] = model_code_;
        scan_times_.reset();
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
        img.set_bit(Area::M, sp::kRun, true);
    }

    void scan_end(const engine::ScanContext& ctx,
                  const engine::Calendar& c,
                  std::uint8_t& station) noexcept override {
        auto* r = ctx.image.words(Area::R);
        // R4055: a master sets the station by writing 55h in the high byte (FBs manual,
        // R4055; docs/profile-fbs.md, "Modbus map").
        const std::uint16_t st = r[sp::kStation];
        if ((st >> 8) == 0x55 && (st & 0xFF) >= 1 && (st & 0xFF) <= 254) {
            station = static_cast<std::uint8_t>(st & 0xFF);
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
    }

private:
    std::uint16_t model_code_;
    engine::ScanTimes scan_times_{std::chrono::milliseconds(1)};
};

}  // namespace

std::unique_ptr<engine::Specials> make_specials(std::uint16_t model_code) {
    return std::make_unique<FbsSpecials>(model_code);
}

}  // namespace plcemu::profiles::fbs
