// The count of open descriptors the listeners leave their clients room by
// (src/daemon/fd_limit.cpp).

#include <fcntl.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include <array>
#include <filesystem>

#include "daemon/fd_limit.hpp"

namespace plcemu::daemon {
namespace {

// The entries of /proc/self/fd by another reader than the daemon's, less the reader's own
// descriptor.
long listed() {
    long n = 0;
    for (const auto& entry : std::filesystem::directory_iterator("/proc/self/fd")) {
        static_cast<void>(entry);
        ++n;
    }
    return n - 1;
}

TEST(FdLimit, OpenDescriptorsAreCountedAsTheyOpenAndClose) {
    const long before = open_descriptors();
    ASSERT_GT(before, 2);  // at least the standard three
    EXPECT_EQ(before, listed());
    std::array<int, 5> fds{};
    for (int& fd : fds) {
        fd = ::open("/dev/null", O_RDONLY | O_CLOEXEC);
        ASSERT_GE(fd, 0);
    }
    EXPECT_EQ(open_descriptors(), before + 5);
    EXPECT_EQ(open_descriptors(), listed());
    for (const int fd : fds) ::close(fd);
    EXPECT_EQ(open_descriptors(), before);
}

}  // namespace
}  // namespace plcemu::daemon
