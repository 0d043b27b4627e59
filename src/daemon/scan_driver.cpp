#include "scan_driver.hpp"

#include <spdlog/spdlog.h>

#include <algorithm>
#include <ctime>
#include <utility>

namespace plcemu::daemon {

namespace {

// Longest stretch of back-to-back scans before the loop lets I/O in.
constexpr auto kBudget = std::chrono::milliseconds(2);

}  // namespace

void LatenessStats::record(std::chrono::nanoseconds late) noexcept {
    ++scans;
    if (late > max) max = late;
    if (late > std::chrono::milliseconds(1)) ++over_1ms;
    sum += late;
    const auto bucket = static_cast<std::size_t>(late.count() < 0 ? 0 : late / kBucket);
    ++histogram[std::min(bucket, kBuckets - 1)];
}

std::chrono::microseconds LatenessStats::percentile(double fraction) const noexcept {
    const auto wanted = static_cast<std::uint64_t>(fraction * static_cast<double>(scans));
    std::uint64_t seen = 0;
    for (std::size_t i = 0; i < kBuckets; ++i) {
        seen += histogram[i];
        if (seen > wanted || seen == scans) {
            // The bucket's upper edge, but never more than the worst seen.
            return std::min(kBucket * static_cast<long>(i + 1),
                            std::chrono::duration_cast<std::chrono::microseconds>(max));
        }
    }
    return std::chrono::duration_cast<std::chrono::microseconds>(max);
}

engine::DurationHistogram LatenessStats::coarse() const noexcept {
    engine::DurationHistogram h;
    constexpr auto& kBounds = engine::DurationHistogram::kBoundsUs;
    std::size_t fine = 0;
    for (std::size_t b = 0; b < kBounds.size(); ++b) {
        const auto below =
            static_cast<std::size_t>(std::chrono::microseconds(kBounds[b]) / kBucket);
        for (; fine < below && fine < kBuckets; ++fine) h.buckets[b] += histogram[fine];
    }
    for (; fine < kBuckets; ++fine) h.buckets.back() += histogram[fine];
    h.count = scans;
    h.sum = sum;
    return h;
}

ScanDriver::ScanDriver(ScanTimer& timer,
                       StepRounds& rounds,
                       engine::Engine& engine,
                       double time_scale,
                       std::string prefix)
    : timer_(timer),
      slot_(timer.add(*this)),
      rounds_(rounds),
      engine_(engine),
      schedule_(engine.scan_period(), time_scale),
      prefix_(std::move(prefix)) {}

// A reload swaps engines: the rounds must not scan a freed one.
ScanDriver::~ScanDriver() {
    timer_.remove(slot_);
    rounds_.remove(*this);
}

void ScanDriver::start_at(Clock::time_point first) {
    running_ = true;
    last_scan_ = first;
    schedule_.start(
        engine_.scans() == 0 ? engine::Duration{0} : engine_.now() + engine_.scan_period(), first);
    arm();
}

void ScanDriver::stop() {
    running_ = false;
    timer_.cancel(slot_);
}

void ScanDriver::set_time_scale(double scale) noexcept {
    schedule_.set_time_scale(scale, Clock::now());
    arm();
}

void ScanDriver::set_frozen(bool frozen) noexcept {
    if (!schedule_.set_frozen(frozen, Clock::now())) return;
    if (frozen) {
        timer_.cancel(slot_);
    } else {
        last_scan_ = Clock::now();  // the schedule starts again from now
        arm();
    }
}

void ScanDriver::step(std::uint64_t n) noexcept {
    schedule_.queue_steps(n);
    if (schedule_.pending_steps() > 0) rounds_.add(*this);
}

void ScanDriver::cancel_steps() noexcept {
    schedule_.cancel_steps();
    rounds_.remove(*this);
}

bool ScanDriver::step_once() noexcept {
    if (schedule_.pending_steps() == 0) return false;
    run_one(schedule_.next_sim(), Clock::now());
    schedule_.stepped(Clock::now());
    return schedule_.pending_steps() > 0;
}

// The wall clock is read once a second, not once a scan: until the steady clock reaches the
// moment the wall clock's next second begins, the calendar stands. A wall clock set back or
// forward is seen at that moment, at most a second late.
void ScanDriver::update_calendar(Clock::time_point now) {
    if (now < next_second_) return;
    const auto wall_now = std::chrono::system_clock::now();
    const auto wall = std::chrono::system_clock::to_time_t(wall_now);
    const auto into = wall_now - std::chrono::system_clock::from_time_t(wall);
    next_second_ =
        now + std::chrono::duration_cast<Clock::duration>(std::chrono::seconds(1) - into);
    if (wall != calendar_second_) {
        calendar_second_ = wall;
        std::tm tm{};
        localtime_r(&wall, &tm);
        calendar_ = {tm.tm_sec,     tm.tm_min,         tm.tm_hour, tm.tm_mday,
                     tm.tm_mon + 1, tm.tm_year + 1900, tm.tm_wday};
    }
}

void ScanDriver::run_one(engine::Duration sim, Clock::time_point now) {
    update_calendar(now);
    // The station a master asked for is the daemon's to grant, after the scan and before any
    // request is read: a read right after the scan sees the station in force.
    if (const auto wanted = engine_.step(sim, calendar_)) {
        if (!grant_ || grant_(*wanted)) engine_.set_station(*wanted);
    }
    if (history_ != nullptr) history_->after_scan(engine_);
    if (on_scan_) on_scan_(now);
}

void ScanDriver::arm() {
    if (!running_ || schedule_.frozen()) return;
    timer_.schedule(slot_, schedule_.deadline(schedule_.next_sim()));
}

// Stage 0: the engine object and the trends; then the engine's own stages.
void ScanDriver::prefetch(int stage) const noexcept {
    static_assert(Scheduled::kPrefetchStages == engine::Engine::kPrefetchStages + 1);
    if (stage == 0) {
        __builtin_prefetch(&engine_);
        __builtin_prefetch(history_);
        return;
    }
    engine_.prefetch(stage - 1);
}

ScanDriver::Clock::time_point ScanDriver::due(Clock::time_point now) {
    return running_ && !schedule_.frozen() ? tick(now) : now;
}

ScanDriver::Clock::time_point ScanDriver::tick(Clock::time_point start) {
    auto now = start;
    for (auto d = schedule_.due(now); d.scans > 0; d = schedule_.due(now)) {
        lateness_.record(now - d.next_deadline + skipped_);
        skipped_ = {};
        const auto began = now;
        run_one(schedule_.next_sim(), now);
        schedule_.ran();
        now = Clock::now();
        duration_.record(now - began);
        last_scan_ = now;
        if (now - start > kBudget) break;
    }
    const auto behind = now - schedule_.deadline(schedule_.next_sim());
    if (schedule_.skip_ahead(now)) {
        // The next scan starts on the new schedule, but as late as the old one said: its
        // lateness counts what was skipped, and the PLC is not on schedule for a while.
        skipped_ = behind;
        previous_skip_ = last_skip_;
        last_skip_ = now;
        spdlog::warn(
            "{}scan: more than {} s behind real time at time scale {}; skipping ahead", prefix_,
            std::chrono::duration_cast<std::chrono::seconds>(ScanSchedule::kMaxBehind).count(),
            schedule_.time_scale());
    }
    arm();
    return now;
}

bool ScanDriver::on_schedule() const noexcept {
    if (!running_) return false;
    if (schedule_.frozen()) return true;
    const auto period = std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(
        std::chrono::duration<double>(engine_.scan_period()).count() / schedule_.time_scale()));
    const auto window = std::max<Clock::duration>(2 * period, std::chrono::seconds(2));
    const auto now = Clock::now();
    // Scans that cannot keep up: the next one is overdue by more than two periods (at least
    // half a second), as a PLC drifting behind is between its skips ahead, or the schedule
    // skipped ahead a second time soon after the first. One skip alone is a pause the scans
    // came out of (the process stopped, the host busy for a moment).
    const bool overdue = now - schedule_.deadline(schedule_.next_sim()) >
                         std::max<Clock::duration>(2 * period, std::chrono::milliseconds(500));
    const bool skipping = previous_skip_ != Clock::time_point{} &&
                          last_skip_ - previous_skip_ < 2 * window && now - last_skip_ < window;
    return now - last_scan_ < window && !overdue && !skipping;
}

}  // namespace plcemu::daemon
