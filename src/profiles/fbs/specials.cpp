#include "profiles/fbs/specials.hpp"

#include <chrono>
#include <string>

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

engine::Tags special_tags() {
    using engine::Number;
    engine::Tags t{
        {{Area::M, sp::kClock10ms, 1}, "special relay: 0.01 s clock"},
        {{Area::M, sp::kClock100ms, 1}, "special relay: 0.1 s clock"},
        {{Area::M, sp::kClock1s, 1}, "special relay: 1 s clock"},
        {{Area::M, sp::kClock60s, 1}, "special relay: 60 s clock"},
        {{Area::M, sp::kFirstScan, 1}, "special relay: first-scan pulse"},
        {{Area::M, sp::kRun, 1}, "special relay: RUN"},
        {{Area::R, sp::kTempMeasureRemap, 1},
         "special register: A55Ah takes the TPCTL PVs from the block R4004 names",
         Number::Unsigned},
        {{Area::R, sp::kTempPvSource, 1},
         "special register: TPCTL PV start (encoded: 10000+n = Rn, 20000+n = Dn)",
         Number::Unsigned},
        {{Area::R, sp::kPidTiming, 1},
         "special register: TPCTL PWM cycle (high byte) and solution interval (low byte) codes",
         Number::Unsigned},
        {{Area::R, sp::kHeaterOpenPercent, 1}, "special register: heater-open detection output, %"},
        {{Area::R, sp::kHeaterOpenSeconds, 1}, "special register: heater-open detection time, s"},
        {{Area::R, sp::kOverTemperature, 1},
         "special register: over-temperature limit, 0.1 degree"},
        {{Area::R, sp::kTempUnit, 1},
         "special register: temperature unit, low byte 0 C, 1 F",
         Number::Unsigned},
        {{Area::R, sp::kSensorInstalled, 2},
         "special register: sensor-installed bits, points 0-15 and 16-31",
         Number::Unsigned},
        {{Area::R, sp::kPidEnable, 2},
         "special register: PID enable bits, points 0-15 and 16-31",
         Number::Unsigned},
        {{Area::R, sp::kTempAverage, 1},
         "special register: temperature moving average, 0-4 = 1, 2, 4, 8, 16 samples",
         Number::Unsigned},
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

std::unique_ptr<engine::Specials> make_specials(std::uint16_t model_code) {
    return std::make_unique<FbsSpecials>(model_code);
}

}  // namespace plcemu::profiles::fbs
