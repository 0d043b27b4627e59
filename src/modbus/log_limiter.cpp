#include "log_limiter.hpp"

#include <spdlog/spdlog.h>

namespace plcemu::modbus {

bool LogLimiter::allow(LogCause cause, Clock::time_point now) noexcept {
    Budget& b = budgets_[static_cast<std::size_t>(cause)];
    // A window with nothing suppressed simply ends; one with suppressed lines ends at flush().
    if (b.suppressed == 0 && now - b.window_start >= window_) {
        b.window_start = now;
        b.logged = 0;
    }
    if (b.logged < burst_) {
        ++b.logged;
        return true;
    }
    ++b.suppressed;
    return false;
}

void LogLimiter::flush_to_log(Clock::time_point now, std::string_view prefix, bool all) noexcept {
    flush(
        now,
        [&](LogCause cause, std::uint64_t n, Clock::duration span) {
            spdlog::warn("{}{} more {} in the last {} s (not logged one by one)", prefix, n,
                         describe(cause),
                         std::chrono::duration_cast<std::chrono::seconds>(span).count());
        },
        all);
}

std::string_view describe(LogCause cause) noexcept {
    switch (cause) {
        case LogCause::RefusedNotAllowed:
            return "connections refused (not in the allow list)";
        case LogCause::RefusedFull:
            return "connections refused (max_clients reached)";
        case LogCause::Connected:
            return "connects";
        case LogCause::Disconnected:
            return "disconnects";
        case LogCause::StationTaken:
            return "station changes refused (R4055)";
        case LogCause::BadHeader:
            return "bad MBAP headers";
        case LogCause::FrameLeft:
            return "reconnects for part of a frame left";
        case LogCause::Flood:
            return "connections closed for bytes not asked for";
        case LogCause::CommFault:
            return "communication faults switched on or off";
        case LogCause::DatagramRefused:
            return "datagrams ignored (not in the allow list)";
        case LogCause::SyncFailed:
            return "state files failing to sync";
        case LogCause::SyncResumed:
            return "state files syncing again";
        case LogCause::StateFileGone:
            return "state files deleted or moved away while in use";
        case LogCause::Count:
            break;
    }
    return "lines";
}

}  // namespace plcemu::modbus
