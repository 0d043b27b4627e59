#include "plcemu/listener/unit_table.hpp"

namespace plcemu::listener {

Hit UnitTable::find(std::uint8_t unit, bool device_itself) noexcept {
    // A plain search: stations change at run time (R4055), a listener holds at most a few hundred
    // PLCs, and two bytes per PLC are compared.
    for (const Seat& s : seats_) {
        if (*s.station == unit) return {&s, false, unit};
        if (s.simulator != nullptr && s.simulator_unit == unit) return {&s, true, unit};
    }
    if (device_itself && seats_.size() == 1) {
        const Seat& s = seats_.front();
        return {&s, false, *s.station};
    }
    ++stats_.unrouted;
    return {};
}

}  // namespace plcemu::listener
