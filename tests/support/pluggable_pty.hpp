#pragma once
// Test support: a pty standing in for a serial device that can be unplugged and plugged back.

#include <fcntl.h>
#include <gtest/gtest.h>
#include <termios.h>
#include <unistd.h>

#include <array>
#include <cstdlib>
#include <string>

namespace plcemu::testing {

// A serial device that can be unplugged and plugged back: a pty whose slave end is reached
// through a link, as socat's pty pairs are, and comes back under the same link.
class PluggablePty {
public:
    explicit PluggablePty(std::string link)
        : link_(std::move(link)) {
        plug();
    }
    ~PluggablePty() { unplug(); }
    PluggablePty(const PluggablePty&) = delete;
    PluggablePty& operator=(const PluggablePty&) = delete;

    void plug() {
        master_ = ::posix_openpt(O_RDWR | O_NOCTTY | O_NONBLOCK | O_CLOEXEC);
        ASSERT_GE(master_, 0);
        ASSERT_EQ(::grantpt(master_), 0);
        ASSERT_EQ(::unlockpt(master_), 0);
        std::array<char, 128> name{};
        ASSERT_EQ(::ptsname_r(master_, name.data(), name.size()), 0);
        termios tio{};
        ASSERT_EQ(::tcgetattr(master_, &tio), 0);
        ::cfmakeraw(&tio);
        ASSERT_EQ(::tcsetattr(master_, TCSANOW, &tio), 0);
        ::unlink(link_.c_str());
        ASSERT_EQ(::symlink(name.data(), link_.c_str()), 0);
    }

    // Closing the master makes the slave read EIO and its /dev/pts node disappear.
    void unplug() {
        if (master_ >= 0) ::close(master_);
        master_ = -1;
        ::unlink(link_.c_str());
    }

    int master() const { return master_; }
    const std::string& link() const { return link_; }

private:
    std::string link_;
    int master_ = -1;
};

}  // namespace plcemu::testing
