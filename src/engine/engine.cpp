#include "plcemu/engine/engine.hpp"

#include <algorithm>

#include "plcemu/engine/special.hpp"

namespace plcemu::engine {

using image::Area;
namespace sp = special;

Engine::Engine(image::Image& image, EngineOptions options, Program program)
    : image_(image),
      options_(options),
      program_(std::move(program)),
      station_(options.station) {}

void Engine::add_subsystem(std::unique_ptr<Subsystem> s) { subsystems_.push_back(std::move(s)); }

void Engine::power_up() {
    auto* r = image_.words(Area::R);
    r[sp::kPowerUps] = static_cast<std::uint16_t>(r[sp::kPowerUps] + 1);
    // SPEC §5: defaults of R4005–R4008, R4010–R4013 at start.
    r[sp::kPidTiming] = 0x0102;
    r[sp::kHeaterOpenPercent] = 90;
    r[sp::kHeaterOpenSeconds] = 600;
    r[sp::kOverTemperature] = 3500;
    r[sp::kSensorInstalled] = 0xFFFF;
    r[sp::kSensorInstalled + 1] = 0xFFFF;
    r[sp::kPidEnable] = 0xFFFF;
    r[sp::kPidEnable + 1] = 0xFFFF;
    r[sp::kCpuStatus] = 0;
    r[sp::kStation] = station_;
    r[sp::kModelCode] = options_.model_code;
    // Simulated time and the scan-time registers count from this power-up.
    scans_ = 0;
    started_ = false;
    last_ = Duration{0};
    scan_min_ms_ = 0xFFFF;
    scan_max_ms_ = 0;
}

void Engine::special_relays(const ScanContext& ctx) noexcept {
    // Square waves of the simulated clock: ON for the first half of each period. A clock whose
    // half period is shorter than the scan would alias to a constant when sampled at each scan
    // start (M1920 with the default 10 ms scan), so it toggles every scan instead: the fastest
    // wave a program or a master can see.
    auto square = [&](std::chrono::nanoseconds period) {
        const auto half = period / 2;
        if (ctx.dt > half) return ctx.scan % 2 == 0;
        return (ctx.now / half) % 2 == 0;
    };
    using std::chrono::milliseconds;
    using std::chrono::seconds;
    image_.set_bit(Area::M, sp::kClock10ms, square(milliseconds(10)));
    image_.set_bit(Area::M, sp::kClock100ms, square(milliseconds(100)));
    image_.set_bit(Area::M, sp::kClock1s, square(seconds(1)));
    image_.set_bit(Area::M, sp::kClock60s, square(seconds(60)));
    image_.set_bit(Area::M, sp::kFirstScan, ctx.first_scan);
    image_.set_bit(Area::M, sp::kRun, true);
}

void Engine::special_registers(const ScanContext& ctx, const Calendar& c) noexcept {
    auto* r = image_.words(Area::R);
    // R4055: a master sets the station by writing 55h in the high byte (SPEC §2).
    const std::uint16_t st = r[sp::kStation];
    if ((st >> 8) == 0x55 && (st & 0xFF) >= 1 && (st & 0xFF) <= 254) {
        station_ = static_cast<std::uint8_t>(st & 0xFF);
    }
    r[sp::kStation] = station_;
    r[sp::kCpuStatus] = 0;
    r[sp::kModelCode] = options_.model_code;

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

void Engine::step(Duration now, const Calendar& calendar) noexcept {
    const Duration dt = started_ ? now - last_ : options_.scan_period;
    ScanContext ctx{image_, now, dt, scans_, !started_};
    started_ = true;
    last_ = now;
    special_relays(ctx);
    for (auto& s : subsystems_) s->inputs(ctx);
    for (auto& i : program_) i->execute(ctx);
    for (auto it = subsystems_.rbegin(); it != subsystems_.rend(); ++it) (*it)->outputs(ctx);
    special_registers(ctx, calendar);
    ++scans_;
}

void Engine::run_scans(std::uint64_t n, const Calendar& calendar) noexcept {
    for (std::uint64_t i = 0; i < n; ++i) {
        const Duration next = scans_ == 0 && !started_ ? Duration{0} : last_ + options_.scan_period;
        step(next, calendar);
    }
}

}  // namespace plcemu::engine
