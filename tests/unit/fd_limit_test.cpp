// The count of open descriptors the listeners leave their clients room by
// (src/daemon/fd_limit.cpp).

#include <dirent.h>
#include <fcntl.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include <array>

#include "daemon/fd_limit.hpp"

namespace plcemu::daemon {
namespace {

// The entries of /proc/self/fd, less the directory's own descriptor.
long listed() {
    DIR* dir = ::opendir("/proc/self/fd");
    if (dir == nullptr) return -1;
    long n = 0;
    while (const dirent* e = ::readdir(dir)) {
        if (e->d_name[0] != '.') ++n;
    }
    ::closedir(dir);
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
