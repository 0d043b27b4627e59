#pragma once
// Rate limit for log lines that remote peers can cause (refused connects, connects and
// disconnects, refused station changes, an MBUS slave's faults), or a failing disk under
// thousands of state files: the first few lines of each cause in a window are logged, the rest
// are counted and summed up in one line when the window ends. spdlog has no such limit of its
// own.

#include <array>
#include <chrono>
#include <cstddef>
#include <cstdint>
#include <string_view>

namespace plcemu::modbus {

/// What a rate-limited log line is about.
enum class LogCause : std::uint8_t {
    RefusedNotAllowed,  ///< a peer outside modbus.tcp.allow
    RefusedFull,        ///< max_clients reached
    Connected,          ///< a client connected (or the MBUS master to a slave)
    Disconnected,       ///< a client went away or was closed (or a slave's connection)
    StationTaken,       ///< a master asked for a station another unit has (R4055)
    BadHeader,          ///< a slave sent the MBUS master bytes that are no MBAP frame
    FrameLeft,          ///< a slave left part of a frame (its length field lied)
    Flood,              ///< a slave sent the MBUS master more than it asked for
    CommFault,          ///< a communication fault switched on or off (a master may toggle one)
    DatagramRefused,    ///< a datagram from a peer outside a UDP listener's allow list
    SyncFailed,         ///< a state file's sync failed, after good ones
    SyncResumed,        ///< a state file synced again, after failures
    StateFileGone,      ///< a state file deleted or moved away while in use
    Count,
};

/// Per-cause budget of log lines.
class LogLimiter {
public:
    using Clock = std::chrono::steady_clock;

    /// `burst` lines per cause in each `window`.
    LogLimiter(std::size_t burst, Clock::duration window) noexcept
        : burst_(burst),
          window_(window) {}

    /// True when a line for `cause` may be written now; otherwise counts it as suppressed.
    bool allow(LogCause cause, Clock::time_point now) noexcept;

    /// For each cause whose window is over with lines suppressed: calls `report(cause, count,
    /// span)` once (`span`: since the window began, the window or longer when flushed late) and
    /// starts a new window. Call it now and then (the transports' sweep timer does).
    /// `all`: every cause with lines suppressed, its window over or not (the listener closes).
    template <typename F>
    void flush(Clock::time_point now, F&& report, bool all = false) {
        for (std::size_t i = 0; i < budgets_.size(); ++i) {
            Budget& b = budgets_[i];
            if (b.suppressed == 0 || (!all && now - b.window_start < window_)) continue;
            report(static_cast<LogCause>(i), b.suppressed, now - b.window_start);
            b = Budget{};
        }
    }

    /// True while some cause has lines held back, to be summed up by flush().
    bool holding() const noexcept {
        for (const Budget& b : budgets_) {
            if (b.suppressed != 0) return true;
        }
        return false;
    }

    /// flush() as warnings: "PREFIX N more CAUSE in the last S s (not logged one by one)", S the
    /// whole seconds since the window began.
    void flush_to_log(Clock::time_point now, std::string_view prefix, bool all = false) noexcept;

private:
    struct Budget {
        Clock::time_point window_start{};
        std::size_t logged = 0;
        std::uint64_t suppressed = 0;
    };

    std::size_t burst_;
    Clock::duration window_;
    std::array<Budget, static_cast<std::size_t>(LogCause::Count)> budgets_{};
};

/// A few words for a cause, for the summary line ("refused: not in modbus.tcp.allow").
std::string_view describe(LogCause cause) noexcept;

}  // namespace plcemu::modbus
