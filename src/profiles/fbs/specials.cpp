#include "profiles/fbs/specials.hpp"

#include <algorithm>
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
        scan_min_ms_ = 0xFFFF;
        scan_max_ms_ = 0;
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

        r[sp::kCalendar + 0] = static_cast<std::uint16_t>(c.second);
        r[sp::kCalendar + 1] = static_cast<std::uint16_t>(c.minute);
        r[sp::kCalendar + 2] = static_cast<std::uint16_t>(c.hour);
        r[sp::kCalendar + 3] = static_cast<std::uint16_t>(c.day);
        r[sp::kCalendar + 4] = static_cast<std::uint16_t>(c.month);
        r[sp::kCalendar + 5] = static_cast<std::uint16_t>(c.year % 100);
        r[sp::kCalendar + 6] = static_cast<std::uint16_t>(c.weekday);

        // Scan time: the simulated interval between scan starts, in ms (deterministic; equal to
        // scan_ms while the engine keeps its period).
        const auto ms = std::chrono::duration_cast<std::chrono::milliseconds>(ctx.dt).count();
        const auto cur = static_cast<std::uint16_t>(std::clamp<long long>(ms, 0, 0xFFFF));
        scan_max_ms_ = std::max(scan_max_ms_, cur);
        scan_min_ms_ = std::min(scan_min_ms_, cur);
        r[sp::kScanTime] = cur;
        r[sp::kScanTime + 1] = scan_max_ms_;
        r[sp::kScanTime + 2] = scan_min_ms_;
    }

private:
    std::uint16_t model_code_;
    std::uint16_t scan_min_ms_ = 0xFFFF;
    std::uint16_t scan_max_ms_ = 0;
};

}  // namespace

std::unique_ptr<engine::Specials> make_specials(std::uint16_t model_code) {
    return std::make_unique<FbsSpecials>(model_code);
}

}  // namespace plcemu::profiles::fbs
