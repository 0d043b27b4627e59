#include "daemon/background.hpp"

#include <sys/resource.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>

namespace plcemu::daemon {

void yield_to_the_loop() noexcept {
    // Linux keeps a nice value per thread: PRIO_PROCESS with a thread's id sets that thread's
    // alone (setpriority(2), "Bugs"), which POSIX's per-process nice cannot express.
    errno = 0;
    const int process = ::getpriority(PRIO_PROCESS, static_cast<id_t>(::getpid()));
    if (process == -1 && errno != 0) return;
    ::setpriority(PRIO_PROCESS, static_cast<id_t>(::gettid()), std::min(process + 10, 19));
}

}  // namespace plcemu::daemon
