#pragma once
// Whether the daemon grants a PLC the station a master asked for through R4055, which the scan
// reports (engine::Engine::step): not one that another unit on its listeners answers
// (docs/configuration.md, "Sharing a listener"). A refusal is logged, rate-limited: a master
// retrying every scan must not flood the log.

#include <cstddef>
#include <cstdint>
#include <string>

#include "daemon/listeners.hpp"
#include "modbus/log_limiter.hpp"

namespace plcemu::daemon {

/// The stations taken for the PLC at `index` of the listeners.
class ListenerStationGuard {
public:
    /// `listeners` must outlive the guard; `label` names the PLC in log lines ("" for the one
    /// PLC of a plain config).
    ListenerStationGuard(const Listeners& listeners, std::size_t index, std::string label);

    /// True when `station` is served by something other than this PLC's station on one of its
    /// listeners; the PLC then keeps the station it has, and the refusal is logged.
    bool taken(std::uint8_t station) const noexcept;

private:
    const Listeners& listeners_;
    std::size_t index_;
    std::string prefix_;                  // "plcs[1] (kiln): "
    mutable modbus::LogLimiter limiter_;  // the refusals logged
};

}  // namespace plcemu::daemon
