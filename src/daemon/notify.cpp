#include "notify.hpp"

#include <spdlog/spdlog.h>

#include <cstdlib>

#ifdef PLCEMU_HAVE_SYSTEMD
    #include <systemd/sd-daemon.h>
#endif

namespace plcemu::daemon {

namespace {

// `status` cut to Notifier::kStatusRoom bytes, not inside a UTF-8 sequence.
std::string fitted(const std::string& status) {
    if (status.size() <= Notifier::kStatusRoom) return status;
    std::size_t n = Notifier::kStatusRoom;
    while (n > 0 && (static_cast<unsigned char>(status[n]) & 0xC0) == 0x80) --n;
    return status.substr(0, n);
}

}  // namespace

Notifier::Notifier() {
#ifdef PLCEMU_HAVE_SYSTEMD
    const char* socket = std::getenv("NOTIFY_SOCKET");
    listening_ = socket != nullptr && *socket != '\0';
    std::uint64_t usec = 0;
    // 0 = the manager's environment asks for no pings (or names another PID).
    if (sd_watchdog_enabled(0, &usec) > 0) interval_ = std::chrono::microseconds(usec);
#endif
    if (watchdog_enabled()) {
        spdlog::info("systemd watchdog: {} ms, pinging every {} ms", interval_.count() / 1000,
                     interval_.count() / 4000);
    }
}

void Notifier::send(const std::string& text) noexcept {
#ifdef PLCEMU_HAVE_SYSTEMD
    const int r = sd_notify(0, text.c_str());
    if (r < 0) spdlog::debug("sd_notify failed: {}", r);
#else
    (void)text;
#endif
}

void Notifier::ready(const std::string& status) noexcept {
    send("READY=1\nSTATUS=" + fitted(status));
}

void Notifier::status(const std::string& status) noexcept { send("STATUS=" + fitted(status)); }

void Notifier::reloading() noexcept { send("RELOADING=1\nSTATUS=reloading the configuration"); }

void Notifier::stopping() noexcept { send("STOPPING=1\nSTATUS=stopping"); }

void Notifier::watchdog() noexcept {
    if (!watchdog_enabled()) return;
    ++pings_;
    send("WATCHDOG=1");
}

}  // namespace plcemu::daemon
