#include "step_rounds.hpp"

#include <spdlog/spdlog.h>

#include <algorithm>
#include <exception>

namespace plcemu::daemon {

void StepRounds::add(Stepper& s) noexcept {
    // Called on the request path: out of memory here leaves the steps queued in their driver,
    // taken into the rounds at the next request that asks for steps.
    try {
        if (std::find(queue_.begin(), queue_.end(), &s) == queue_.end()) queue_.push_back(&s);
        post();
    } catch (const std::exception& e) {
        spdlog::error("stepping: {}; the scans asked for wait for the next step request", e.what());
    }
}

void StepRounds::remove(Stepper& s) noexcept {
    queue_.erase(std::remove(queue_.begin(), queue_.end(), &s), queue_.end());
}

void StepRounds::post() {
    if (posted_ || queue_.empty()) return;
    posted_ = true;
    asio::post(io_, [this, alive = std::weak_ptr<char>(alive_)] {
        if (!alive.expired()) round();
    });
}

void StepRounds::round() {
    posted_ = false;
    // One scan per stepper in turn: ten stepped PLCs share the slice one PLC would have had. A
    // clock read costs tens of ns, a scan of a big program milliseconds: look after every scan.
    const auto start = Clock::now();
    while (!queue_.empty()) {
        Stepper* s = queue_.front();
        queue_.pop_front();
        if (s->step_once()) queue_.push_back(s);
        if (Clock::now() - start >= slice_) break;
    }
    // The rest after whatever else is waiting on the loop.
    post();
}

}  // namespace plcemu::daemon
