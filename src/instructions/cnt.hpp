#pragma once
// CNT: a counter of the FX family, counting the rising edges of its input.

#include <memory>

#include "plcemu/engine/engine.hpp"
#include "plcemu/instructions/instructions.hpp"

namespace plcemu::instructions {

/// `CNT: {en: M9013, c: C1, k: 3600}`: each OFF→ON of EN counts. A 16-bit counter counts up to
/// K and stops there; a 32-bit counter counts up or down (down while its direction relay is
/// ON) through the whole 32-bit range. The contact is ON while the value is at least K (a down
/// counter: until it falls below K). K is a constant or a word device.
std::unique_ptr<engine::Instruction> make_cnt(const Entry& ic, const BindContext& ctx);

/// Where a family keeps the count direction of its 32-bit counters: relay `first_relay` + (n −
/// first counter) is the direction of counter n (ON = down) for the first `counters` 32-bit
/// counters; the others always count up.
struct CounterDirection {
    image::Area area = image::Area::M;  ///< the relays' area
    std::uint32_t first_relay = 0;      ///< relay of the first 32-bit counter
    std::uint32_t counters = 0;         ///< how many 32-bit counters have a direction relay
};

/// The services CNT needs, offered by the families that have it. The base is virtual so that a
/// family offers these and other instructions' services (TimerServices) in one object.
struct CounterServices : virtual Services {
    CounterDirection direction;  ///< direction relays of the 32-bit counters
};

}  // namespace plcemu::instructions
