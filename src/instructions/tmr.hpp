#pragma once
// TMR: an on-delay timer of the FX family (OUT T with its set value K).

#include <cstdint>
#include <memory>
#include <vector>

#include "plcemu/engine/engine.hpp"
#include "plcemu/instructions/instructions.hpp"

namespace plcemu::instructions {

/// `TMR: {en: M9000, t: T0, k: 20}`: while EN is ON, the time since the previous scan is added
/// to the timer's value in units of its time base, up to K; the contact is ON while the value
/// is at least K. EN OFF clears value and contact, except for a retentive timer, which keeps
/// both until a RST. K is a constant or a word device.
std::unique_ptr<engine::Instruction> make_tmr(const Entry& ic, const BindContext& ctx);

/// A run of timers sharing a time base: timers `first` … `first` + `count` − 1.
struct TimerGroup {
    std::uint32_t first = 0;  ///< first timer number
    std::uint32_t count = 0;  ///< how many
    engine::Duration base{};  ///< one count of the value
    bool retentive = false;   ///< keeps value and contact while EN is OFF
};

/// The services TMR needs, offered by the families that have it: the time base of each timer.
struct TimerServices : virtual Services {
    std::vector<TimerGroup> timers;  ///< a timer in none of them cannot be used
};

}  // namespace plcemu::instructions
