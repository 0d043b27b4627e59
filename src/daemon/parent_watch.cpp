#include "parent_watch.hpp"

#include <spdlog/spdlog.h>
#include <sys/types.h>
#include <unistd.h>

#include <cerrno>
#include <climits>
#include <csignal>
#include <cstdlib>

#ifdef __linux__
    #include <sys/prctl.h>
#endif

namespace plcemu::daemon {

bool watch_parent() noexcept {
    const char* text = std::getenv("PLCEMUD_PARENT_PID");
    if (text == nullptr || *text == '\0') return true;
    char* end = nullptr;
    errno = 0;
    const long pid = std::strtol(text, &end, 10);
    // A pid_t is an int: a larger value (or one strtol clamped) names no process.
    if (*end != '\0' || errno == ERANGE || pid <= 1 || pid > INT_MAX) {
        spdlog::warn("PLCEMUD_PARENT_PID={}: not a process ID; ignored", text);
        return true;
    }
#ifdef __linux__
    // The kernel sends the signal when the thread that forked plcemud exits (for the kit:
    // pytest's main thread, which lives as long as the session).
    if (prctl(PR_SET_PDEATHSIG, SIGTERM) != 0) {
        spdlog::warn(
            "PLCEMUD_PARENT_PID: prctl(PR_SET_PDEATHSIG) failed; plcemud will not stop "
            "with its parent");
        return true;
    }
    // A parent that died between the fork and the prctl sends nothing: plcemud has been
    // reparented. A wrapper between the two (a script that does not exec) is left alone while
    // the process named is alive.
    if (getppid() != static_cast<pid_t>(pid) && kill(static_cast<pid_t>(pid), 0) != 0 &&
        errno == ESRCH) {
        spdlog::info("PLCEMUD_PARENT_PID={}: that process is gone; not starting", pid);
        return false;
    }
#else
    spdlog::warn("PLCEMUD_PARENT_PID: not supported on this system; ignored");
#endif
    return true;
}

}  // namespace plcemu::daemon
