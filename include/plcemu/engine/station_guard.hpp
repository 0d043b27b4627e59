#pragma once
// The unit IDs a PLC may not take as its station at run time (R4055), because something else
// answers them on one of its listeners: another PLC's live station or a simulator unit
// (docs/configuration.md, "Sharing a listener"). The daemon, which knows the listeners,
// implements it; a family's specials ask it before changing the station.

#include <cstdint>

namespace plcemu::engine {

/// Which stations are taken for one PLC.
class StationGuard {
public:
    virtual ~StationGuard() = default;
    /// True when `station` is served by something other than this PLC's station on one of its
    /// listeners; the PLC then keeps the station it has. The guard may log the refusal.
    virtual bool taken(std::uint8_t station) const noexcept = 0;
};

}  // namespace plcemu::engine
