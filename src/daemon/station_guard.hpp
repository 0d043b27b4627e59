#pragma once
// The daemon's answer to a PLC's engine asking whether a master may give it a station through
// R4055: not one that another unit on its listeners answers (docs/configuration.md, "Sharing a
// listener"). A refusal is logged, rate-limited: a master retrying every scan must not flood
// the log.

#include <cstddef>
#include <string>

#include "daemon/listeners.hpp"
#include "modbus/log_limiter.hpp"
#include "plcemu/engine/station_guard.hpp"

namespace plcemu::daemon {

/// The stations taken for the PLC at `index` of the listeners.
class ListenerStationGuard final : public engine::StationGuard {
public:
    /// `listeners` must outlive the guard; `label` names the PLC in log lines ("" for the one
    /// PLC of a plain config).
    ListenerStationGuard(const Listeners& listeners, std::size_t index, std::string label);

    bool taken(std::uint8_t station) const noexcept override;

private:
    const Listeners& listeners_;
    std::size_t index_;
    std::string prefix_;                  // "plcs[1] (kiln): "
    mutable modbus::LogLimiter limiter_;  // the refusals logged
};

}  // namespace plcemu::daemon
