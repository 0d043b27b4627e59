// The service-manager notifications (docs/operations.md, "Running as a service"): the messages
// sd_notify sends to NOTIFY_SOCKET, read here from a datagram socket standing in for systemd,
// and the watchdog pings only when the manager asks for them. On Linux the build always has
// libsystemd (CMakeLists.txt), so the messages are real.

#include "daemon/notify.hpp"

#include <gtest/gtest.h>
#include <poll.h>
#include <sys/socket.h>
#include <sys/un.h>
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <optional>
#include <string>

namespace plcemu::daemon {
namespace {

using namespace std::chrono_literals;

// A datagram socket bound to a fresh path, named by NOTIFY_SOCKET while it lives (with
// WATCHDOG_USEC as given, and no WATCHDOG_PID: the pings are for this process).
class FakeManager {
public:
    explicit FakeManager(const char* watchdog_usec) {
        path_ = (std::filesystem::temp_directory_path() /
                 ("plcemu-notify-" + std::to_string(::getpid()) + "-" + std::to_string(counter_++)))
                    .string();
        std::filesystem::remove(path_);
        fd_ = ::socket(AF_UNIX, SOCK_DGRAM | SOCK_CLOEXEC, 0);
        sockaddr_un a{};
        a.sun_family = AF_UNIX;
        std::snprintf(a.sun_path, sizeof a.sun_path, "%s", path_.c_str());
        bound_ = fd_ >= 0 && ::bind(fd_, reinterpret_cast<sockaddr*>(&a), sizeof a) == 0;
        ::setenv("NOTIFY_SOCKET", path_.c_str(), 1);
        ::unsetenv("WATCHDOG_PID");
        if (watchdog_usec != nullptr) {
            ::setenv("WATCHDOG_USEC", watchdog_usec, 1);
        } else {
            ::unsetenv("WATCHDOG_USEC");
        }
    }
    ~FakeManager() {
        ::unsetenv("NOTIFY_SOCKET");
        ::unsetenv("WATCHDOG_USEC");
        if (fd_ >= 0) ::close(fd_);
        std::filesystem::remove(path_);
    }
    FakeManager(const FakeManager&) = delete;
    FakeManager& operator=(const FakeManager&) = delete;

    bool bound() const { return bound_; }

    // The next message, or nothing within 200 ms (sd_notify has sent it before it returns).
    std::optional<std::string> next() const {
        pollfd p{fd_, POLLIN, 0};
        if (::poll(&p, 1, 200) <= 0) return std::nullopt;
        // Larger than systemd takes (it ignores 4,096 bytes or more): a message too long is seen
        // whole here.
        std::string buf(1 << 16, '\0');
        const auto n = ::recv(fd_, buf.data(), buf.size(), 0);
        if (n < 0) return std::nullopt;
        buf.resize(static_cast<std::size_t>(n));
        return buf;
    }

private:
    static inline int counter_ = 0;
    std::string path_;
    int fd_ = -1;
    bool bound_ = false;
};

TEST(Notifier, SendsReadyStatusReloadingAndStopping) {
    FakeManager m(nullptr);
    ASSERT_TRUE(m.bound());
    Notifier n;
    EXPECT_FALSE(n.watchdog_enabled());
    n.ready("station 1, tcp 127.0.0.1:5020");
    EXPECT_EQ(m.next(), "READY=1\nSTATUS=station 1, tcp 127.0.0.1:5020");
    n.reloading();
    EXPECT_EQ(m.next(), "RELOADING=1\nSTATUS=reloading the configuration");
    n.status("x");
    EXPECT_EQ(m.next(), "STATUS=x");
    n.stopping();
    EXPECT_EQ(m.next(), "STOPPING=1\nSTATUS=stopping");
    // Without a watchdog, no ping whatever the scans do.
    n.watchdog();
    EXPECT_EQ(m.next(), std::nullopt);
    EXPECT_EQ(n.pings(), 0u);
}

// systemd ignores a whole notification of 4,096 bytes or more (READY=1 with it): a status too
// long is cut, and not inside a character.
TEST(Notifier, AStatusTooLongForTheManagerIsCutToFitAtACharactersStart) {
    FakeManager m(nullptr);
    ASSERT_TRUE(m.bound());
    Notifier n;
    EXPECT_TRUE(n.listening());
    std::string status = "x";
    for (int i = 0; i < 3000; ++i) status += "\xc3\xa9";  // "é", two bytes
    n.ready(status);
    const auto ready = m.next();
    ASSERT_TRUE(ready.has_value());
    EXPECT_EQ(ready->size(), 4094u);  // 4095 would cut the last "é" in two
    EXPECT_EQ(ready->substr(0, 16), "READY=1\nSTATUS=x");
    EXPECT_EQ(ready->substr(ready->size() - 2), "\xc3\xa9");
    n.status(status);
    const auto plain = m.next();
    ASSERT_TRUE(plain.has_value());
    EXPECT_EQ(*plain, "STATUS=" + ready->substr(15));
    // A status that fits goes whole.
    n.status(status.substr(0, 3999));
    EXPECT_EQ(m.next(), "STATUS=" + status.substr(0, 3999));
}

TEST(Notifier, NoManagerNoListening) {
    ::unsetenv("NOTIFY_SOCKET");
    EXPECT_FALSE(Notifier().listening());
}

// The daemon's timer decides when (every quarter interval); each call is a ping.
TEST(Notifier, PingsTheWatchdogEachTimeItIsAskedWhenTheManagerExpectsIt) {
    FakeManager m("2000000");  // WatchdogSec=2s
    ASSERT_TRUE(m.bound());
    Notifier n;
    ASSERT_TRUE(n.watchdog_enabled());
    EXPECT_EQ(n.watchdog_interval(), 2s);
    n.watchdog();
    EXPECT_EQ(m.next(), "WATCHDOG=1");
    n.watchdog();
    EXPECT_EQ(m.next(), "WATCHDOG=1");
    EXPECT_EQ(m.next(), std::nullopt);
    EXPECT_EQ(n.pings(), 2u);
}

// A manager that asks another process for the pings (WATCHDOG_PID) gets none from this one.
TEST(Notifier, NoWatchdogForAnotherProcess) {
    FakeManager m("2000000");
    ::setenv("WATCHDOG_PID", std::to_string(::getpid() + 1).c_str(), 1);
    Notifier n;
    ::unsetenv("WATCHDOG_PID");
    EXPECT_FALSE(n.watchdog_enabled());
    n.watchdog();
    EXPECT_EQ(m.next(), std::nullopt);
}

}  // namespace
}  // namespace plcemu::daemon
