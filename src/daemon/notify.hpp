#pragma once
// systemd service notifications (sd_notify): READY, STATUS, RELOADING, STOPPING and watchdog
// pings. Built without libsystemd (PLCEMU_HAVE_SYSTEMD undefined) every call does nothing.

#include <chrono>
#include <cstddef>
#include <string>

namespace plcemu::daemon {

/// Talks to the service manager that started the daemon, if any (NOTIFY_SOCKET).
class Notifier {
public:
    /// Reads the watchdog interval the manager asked for (WatchdogSec=, WATCHDOG_USEC).
    Notifier();

    /// The longest status a message carries: systemd ignores a whole notification of
    /// NOTIFY_BUFFER_MAX (PIPE_BUF, 4,096) bytes or more, READY=1 included, so ready() and
    /// status() cut a longer one (at a character's start).
    static constexpr std::size_t kStatusRoom =
        4095 - std::char_traits<char>::length("READY=1\nSTATUS=");

    /// True when a service manager listens (NOTIFY_SOCKET is set): a status need not be made
    /// otherwise.
    bool listening() const { return listening_; }

    /// READY=1 with a status line: every listener is open.
    void ready(const std::string& status) noexcept;
    /// STATUS=…
    void status(const std::string& status) noexcept;
    /// RELOADING=1: a SIGHUP reload has begun (ready() ends it).
    void reloading() noexcept;
    /// STOPPING=1: shutting down.
    void stopping() noexcept;

    /// True when the manager expects watchdog pings.
    bool watchdog_enabled() const { return interval_.count() > 0; }
    /// The manager's watchdog interval (0 when disabled).
    std::chrono::microseconds watchdog_interval() const { return interval_; }
    /// Sends WATCHDOG=1 when the manager expects pings (the daemon calls it from a timer on the
    /// scans' event loop every quarter interval: a loop that stops turning stops the pings, and
    /// systemd restarts the service).
    void watchdog() noexcept;
    /// Pings sent so far.
    unsigned long pings() const { return pings_; }

private:
    void send(const std::string& text) noexcept;

    bool listening_ = false;
    std::chrono::microseconds interval_{0};
    unsigned long pings_ = 0;
};

}  // namespace plcemu::daemon
