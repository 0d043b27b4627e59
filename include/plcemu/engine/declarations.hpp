#pragma once
// What a built program says about itself, so that other parts meet it without knowing its
// instructions: which outputs drive which process channel (the plant attaches to them), and
// which devices an instruction owns (a later instruction may not write into them) or reads as its
// settings (where a profile may refuse another instruction's writes).

#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "plcemu/image/area.hpp"

namespace plcemu::engine {

/// An output that drives the actuator of a process channel (a PWM heater output).
struct Actuator {
    int channel = 0;       ///< process channel (0-based)
    image::Device output;  ///< the bit the program switches
};

/// What an instruction's devices are for, when another instruction must not share them.
enum class ClaimKind : std::uint8_t {
    Working,  ///< working registers the instruction keeps its state in
    Output,   ///< values it writes (every scan, or once: a loop's default gains)
    Pwm,      ///< bits it switches as time-proportioning outputs
    Read,     ///< settings it only reads (setpoints), which another instruction's claim may
              ///< not write
};

/// Devices an instruction owns, or (ClaimKind::Read) reads.
struct Claim {
    image::Range range;         ///< the devices
    ClaimKind kind;             ///< what they are for
    std::string_view mnemonic;  ///< the instruction's mnemonic
    std::string where;          ///< the program entry's "file:line:col"
};

/// The declarations of a program, in program order.
struct Declarations {
    std::vector<Actuator> actuators;  ///< outputs that drive process channels
    std::vector<Claim> claims;        ///< devices instructions own
};

}  // namespace plcemu::engine
