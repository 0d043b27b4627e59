#include "fd_limit.hpp"

#include <spdlog/spdlog.h>
#include <sys/resource.h>

namespace plcemu::daemon {

long ensure_fd_limit(int max_clients) noexcept {
    rlimit rl{};
    if (::getrlimit(RLIMIT_NOFILE, &rl) != 0) return -1;
    const rlim_t needed = static_cast<rlim_t>(max_clients) + static_cast<rlim_t>(kFdReserve);
    if (rl.rlim_cur != RLIM_INFINITY && rl.rlim_cur < needed) {
        // The soft limit is ours to raise, up to the hard one (as systemd's LimitNOFILE= is).
        rlimit raised = rl;
        raised.rlim_cur =
            rl.rlim_max == RLIM_INFINITY || rl.rlim_max >= needed ? needed : rl.rlim_max;
        if (::setrlimit(RLIMIT_NOFILE, &raised) == 0) {
            spdlog::info("descriptor limit raised from {} to {} for modbus.tcp.max_clients {}",
                         static_cast<long>(rl.rlim_cur), static_cast<long>(raised.rlim_cur),
                         max_clients);
            rl = raised;
        }
    }
    if (rl.rlim_cur != RLIM_INFINITY && rl.rlim_cur < needed) {
        spdlog::warn(
            "modbus.tcp.max_clients {} needs about {} descriptors but the limit is {}: clients "
            "beyond {} will wait at accept (raise LimitNOFILE= or ulimit -n)",
            max_clients, static_cast<long>(needed), static_cast<long>(rl.rlim_cur),
            static_cast<long>(rl.rlim_cur) - kFdReserve);
    }
    return rl.rlim_cur == RLIM_INFINITY ? -1 : static_cast<long>(rl.rlim_cur);
}

}  // namespace plcemu::daemon
