#include "scan_driver.hpp"

#include <spdlog/spdlog.h>

#include <algorithm>
#include <ctime>
#include <utility>

namespace plcemu::daemon {

namespace {

// Longest stretch of back-to-back scans before the loop lets I/O in.
constexpr auto kBudget = std::chrono::milliseconds(2);
// Scans that may be queued at once (46 simulated hours at 10 ms).
constexpr std::uint64_t kMaxPendingSteps = 16'777'215;
// Further behind than this, the driver stops trying to catch up.
constexpr auto kMaxBehind = std::chrono::seconds(1);

}  // namespace

void LatenessStats::record(std::chrono::nanoseconds late) noexcept {
    ++scans;
    if (late > max) max = late;
    if (late > std::chrono::milliseconds(1)) ++over_1ms;
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

ScanDriver::ScanDriver(ScanTimer& timer,
                       StepRounds& rounds,
                       engine::Engine& engine,
                       double time_scale,
                       std::string prefix)
    : timer_(timer),
      slot_(timer.add(*this)),
      rounds_(rounds),
      engine_(engine),
      scale_(time_scale),
      prefix_(std::move(prefix)) {}

// A reload swaps engines: the rounds must not scan a freed one.
ScanDriver::~ScanDriver() {
    timer_.remove(slot_);
    rounds_.remove(*this);
}

void ScanDriver::start_at(Clock::time_point first) {
    running_ = true;
    next_sim_ = engine_.scans() == 0 ? engine::Duration{0} : engine_.now() + engine_.scan_period();
    rebase(first);
    arm();
}

void ScanDriver::stop() {
    running_ = false;
    timer_.cancel(slot_);
}

void ScanDriver::rebase(Clock::time_point real_now) {
    base_real_ = real_now;
    base_sim_ = next_sim_;
}

ScanDriver::Clock::time_point ScanDriver::deadline(engine::Duration sim) const {
    const auto real = std::chrono::duration<double, std::nano>(
        static_cast<double>((sim - base_sim_).count()) / scale_);
    return base_real_ + std::chrono::duration_cast<Clock::duration>(real);
}

void ScanDriver::set_time_scale(double scale) noexcept {
    rebase(Clock::now());
    scale_ = scale;
    if (running_ && !frozen_) arm();
}

void ScanDriver::set_frozen(bool frozen) noexcept {
    if (frozen == frozen_) return;
    frozen_ = frozen;
    if (frozen_) {
        timer_.cancel(slot_);
    } else {
        rebase(Clock::now());
        if (running_) arm();
    }
}

void ScanDriver::step(std::uint64_t n) noexcept {
    // A bound on what clients can queue: hours of simulated time, never an endless busy loop.
    pending_steps_ = std::min(pending_steps_ + std::min(n, kMaxPendingSteps), kMaxPendingSteps);
    if (pending_steps_ > 0) rounds_.add(*this);
}

void ScanDriver::cancel_steps() noexcept {
    pending_steps_ = 0;
    rounds_.remove(*this);
}

bool ScanDriver::step_once() noexcept {
    if (pending_steps_ == 0) return false;
    run_one(next_sim_);
    next_sim_ += engine_.scan_period();
    --pending_steps_;
    // A running (not frozen) PLC goes on in real time from here, not catching up on the steps.
    if (!frozen_) rebase(Clock::now());
    return pending_steps_ > 0;
}

void ScanDriver::run_one(engine::Duration sim) {
    const auto wall = std::chrono::system_clock::to_time_t(std::chrono::system_clock::now());
    if (wall != calendar_second_) {
        calendar_second_ = wall;
        std::tm tm{};
        localtime_r(&wall, &tm);
        calendar_ = {tm.tm_sec,     tm.tm_min,         tm.tm_hour, tm.tm_mday,
                     tm.tm_mon + 1, tm.tm_year + 1900, tm.tm_wday};
    }
    engine_.step(sim, calendar_);
    if (on_scan_) on_scan_();
}

void ScanDriver::arm() {
    if (!running_ || frozen_) return;
    timer_.schedule(slot_, deadline(next_sim_));
}

void ScanDriver::due() {
    if (running_ && !frozen_) tick();
}

void ScanDriver::tick() {
    const auto start = Clock::now();
    auto now = start;
    while (!frozen_ && deadline(next_sim_) <= now) {
        const auto late = now - deadline(next_sim_);
        lateness_.record(late);
        run_one(next_sim_);
        next_sim_ += engine_.scan_period();
        now = Clock::now();
        if (now - start > kBudget) break;
    }
    if (now - deadline(next_sim_) > kMaxBehind) {
        spdlog::warn("{}scan: more than {} s behind real time at time scale {}; skipping ahead",
                     prefix_, std::chrono::duration_cast<std::chrono::seconds>(kMaxBehind).count(),
                     scale_);
        rebase(now);
    }
    arm();
}

}  // namespace plcemu::daemon
