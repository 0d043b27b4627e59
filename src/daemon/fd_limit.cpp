#include "fd_limit.hpp"

#include <dirent.h>
#include <spdlog/spdlog.h>
#include <sys/resource.h>
#include <sys/stat.h>

#include <string>

namespace plcemu::daemon {

long open_descriptors() noexcept {
    // Linux 6.2 on gives the count as the directory's size: one call, where reading the
    // directory formats an entry for each of the 15,000 descriptors of 5,000 PLCs (20 ms on the
    // event loop, at each reload). Earlier kernels say 0, and the entries are counted.
    struct stat st {};
    if (::stat("/proc/self/fd", &st) == 0 && st.st_size > 0) return static_cast<long>(st.st_size);
    DIR* dir = ::opendir("/proc/self/fd");
    if (dir == nullptr) return -1;
    long n = 0;
    while (const dirent* e = ::readdir(dir)) {
        if (e->d_name[0] != '.') ++n;
    }
    ::closedir(dir);
    return n - 1;  // the directory's own
}

namespace {

rlim_t needed_for(int needed) {
    return static_cast<rlim_t>(needed) + static_cast<rlim_t>(kFdReserve);
}

}  // namespace

void raise_soft_fd_limit(int needed_here, const std::string& what) noexcept {
    rlimit rl{};
    if (::getrlimit(RLIMIT_NOFILE, &rl) != 0) return;
    const rlim_t needed = needed_for(needed_here);
    const bool raisable = rl.rlim_max == RLIM_INFINITY || rl.rlim_max > rl.rlim_cur;
    if (rl.rlim_cur == RLIM_INFINITY || rl.rlim_cur >= needed || !raisable) return;
    // The soft limit is ours to raise, up to the hard one (as systemd's LimitNOFILE= is).
    rlimit raised = rl;
    raised.rlim_cur = rl.rlim_max == RLIM_INFINITY || rl.rlim_max >= needed ? needed : rl.rlim_max;
    if (::setrlimit(RLIMIT_NOFILE, &raised) == 0) {
        spdlog::info("descriptor limit raised from {} to {}{} for {}",
                     static_cast<long>(rl.rlim_cur), static_cast<long>(raised.rlim_cur),
                     raised.rlim_cur < needed ? " (the hard limit)" : "", what);
    }
}

long ensure_fd_limit(int needed_here, const std::string& what, long clients_open) noexcept {
    raise_soft_fd_limit(needed_here, what);
    rlimit rl{};
    if (::getrlimit(RLIMIT_NOFILE, &rl) != 0) return -1;
    const rlim_t needed = needed_for(needed_here);
    if (rl.rlim_cur != RLIM_INFINITY && rl.rlim_cur < needed) {
        const auto limit = static_cast<long>(rl.rlim_cur);
        const long in_use = open_descriptors();
        // What is left once the daemon's own descriptors and its headroom are counted: the
        // clients connected now (at a reload) are not the daemon's own.
        const long room =
            in_use < 0 ? limit - kFdReserve : limit - (in_use - clients_open) - kFdHeadroom;
        const std::string hard = rl.rlim_max == RLIM_INFINITY
                                     ? std::string("unlimited")
                                     : std::to_string(static_cast<long>(rl.rlim_max));
        const std::string clients =
            room > 0 ? "about " + std::to_string(room) +
                           " clients can connect at once, later ones wait at accept"
                     : "the daemon's own descriptors leave none for clients: every connection "
                       "waits at accept";
        spdlog::warn(
            "{} needs about {} descriptors but the limit is {} and cannot be raised (hard limit "
            "{}): {} (raise LimitNOFILE= or ulimit -n)",
            what, static_cast<long>(needed), limit, hard, clients);
    }
    return rl.rlim_cur == RLIM_INFINITY ? -1 : static_cast<long>(rl.rlim_cur);
}

}  // namespace plcemu::daemon
