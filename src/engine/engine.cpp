#include "plcemu/engine/engine.hpp"

#include <algorithm>

namespace plcemu::engine {

Declarations declarations_of(const Program& program) {
    Declarations d;
    for (const auto& i : program) i->declare(d);
    return d;
}

bool square_wave(const ScanContext& ctx, std::chrono::nanoseconds period) noexcept {
    const auto half = period / 2;
    if (ctx.dt > half) return ctx.scan % 2 == 0;
    return (ctx.now / half) % 2 == 0;
}

void write_calendar(std::uint16_t* seven_words, const Calendar& c) noexcept {
    seven_words[0] = static_cast<std::uint16_t>(c.second);
    seven_words[1] = static_cast<std::uint16_t>(c.minute);
    seven_words[2] = static_cast<std::uint16_t>(c.hour);
    seven_words[3] = static_cast<std::uint16_t>(c.day);
    seven_words[4] = static_cast<std::uint16_t>(c.month);
    seven_words[5] = static_cast<std::uint16_t>(c.year % 100);
    seven_words[6] = static_cast<std::uint16_t>(c.weekday);
}

void ScanTimes::update(const ScanContext& ctx) noexcept {
    const auto units = static_cast<long long>(ctx.dt / unit);
    current = static_cast<std::uint16_t>(std::clamp<long long>(units, 0, 0xFFFF));
    min = std::min(min, current);
    max = std::max(max, current);
}

Engine::Engine(image::Image& image,
               EngineOptions options,
               Program program,
               std::unique_ptr<Specials> specials)
    : image_(image),
      options_(options),
      program_(std::move(program)),
      specials_(specials ? std::move(specials) : std::make_unique<NoSpecials>()),
      holds_(image.layout()),
      station_(options.station) {}

void Engine::add_subsystem(std::unique_ptr<Subsystem> s) { subsystems_.push_back(std::move(s)); }

void Engine::power_up() {
    specials_->power_up(image_, station_);
    // Simulated time counts from this power-up.
    scans_ = 0;
    started_ = false;
    last_ = Duration{0};
}

void Engine::reload() { specials_->reload(image_); }

std::optional<std::uint8_t> Engine::step(Duration now, const Calendar& calendar) noexcept {
    const Duration dt = started_ ? now - last_ : options_.scan_period;
    ScanContext ctx{image_,   now,       dt,      scans_, !started_ || first_after_run_,
                    modules_, outbound_, running_};
    started_ = true;
    first_after_run_ = false;
    last_ = now;
    // Disabled discretes keep what a master last wrote: taken before the scan, put back after
    // the I/O refresh and after the program.
    const bool holding = !holds_.empty();
    if (holding) holds_.take(image_);
    specials_->scan_start(ctx);
    for (auto& s : subsystems_) s->inputs(ctx);
    if (holding) holds_.put(image_);
    if (running_) {
        // The program's writes pass the disabled discretes by; the put() after it covers what
        // is written through the image's raw pointers.
        if (holding) image_.hold(&holds_.bits());
        for (auto& i : program_) i->execute(ctx);
        image_.hold(nullptr);
    } else {
        outputs_off();
    }
    if (holding) holds_.put(image_);
    for (auto it = subsystems_.rbegin(); it != subsystems_.rend(); ++it) (*it)->outputs(ctx);
    const auto wanted = specials_->scan_end(ctx, calendar, station_);
    ++scans_;
    return wanted;
}

void Engine::prefetch(int stage) const noexcept {
    if (stage == 0) {
        __builtin_prefetch(program_.data());
        __builtin_prefetch(subsystems_.data());
        __builtin_prefetch(specials_.get());
        return;
    }
    for (const auto& s : subsystems_) __builtin_prefetch(s.get());
    for (const auto& i : program_) __builtin_prefetch(i.get());
}

void Engine::outputs_off() noexcept {
    const std::uint32_t n = image_.layout().size_of(image::Area::Y);
    std::uint8_t* y = image_.bits(image::Area::Y);
    std::fill(y, y + n, std::uint8_t{0});
    if (!holds_.empty()) holds_.put(image_);
}

void Engine::set_running(bool run) noexcept {
    if (run == running_) return;
    running_ = run;
    if (run) {
        specials_->reload(image_);
        first_after_run_ = true;
    } else {
        if (!holds_.empty()) holds_.take(image_);
        outputs_off();
    }
    specials_->run_changed(image_, run);
}

void Engine::set_station(std::uint8_t station) noexcept {
    station_ = station;
    specials_->station_changed(image_, station);
}

void Engine::run_scans(std::uint64_t n, const Calendar& calendar) noexcept {
    for (std::uint64_t i = 0; i < n; ++i) {
        const Duration next = scans_ == 0 && !started_ ? Duration{0} : last_ + options_.scan_period;
        if (const auto wanted = step(next, calendar)) set_station(*wanted);
    }
}

}  // namespace plcemu::engine
