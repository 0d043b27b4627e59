#include "station_guard.hpp"

#include <spdlog/spdlog.h>

#include <chrono>
#include <utility>

namespace plcemu::daemon {

namespace {

// A few lines a minute: a refusal is a master's mistake, logged so that it can be found, not
// once per request of a master that repeats it.
constexpr std::size_t kBurst = 5;
constexpr auto kWindow = std::chrono::seconds(60);

}  // namespace

ListenerStationGuard::ListenerStationGuard(const Listeners& listeners,
                                           std::size_t index,
                                           std::string label)
    : listeners_(listeners),
      index_(index),
      prefix_(label.empty() ? std::string() : std::move(label) + ": "),
      limiter_(kBurst, kWindow) {}

bool ListenerStationGuard::taken(std::uint8_t station) const noexcept {
    try {
        const std::string who = listeners_.holder(index_, station);
        if (who.empty()) return false;
        const auto now = modbus::LogLimiter::Clock::now();
        limiter_.flush_to_log(now, prefix_);
        if (limiter_.allow(modbus::LogCause::StationTaken, now)) {
            spdlog::warn("{}R4055: station {} refused: it is {}; the station stays as it was",
                         prefix_, int(station), who);
        }
        return true;
    } catch (...) {
        // No memory for the message: refuse rather than risk two PLCs on one unit ID.
        return true;
    }
}

}  // namespace plcemu::daemon
