#pragma once
// The control loops of a program, as a faceplate shows them (the console's loops page,
// docs/console.md): where each loop's process value, set point and output are, its tuning
// parameters and alarms, in the program's own devices. An instruction that runs loops (FBs TPCTL,
// VB PID and TPID) describes them; the view reads and writes those devices like any other.
// Nothing here runs during a scan.

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "plcemu/image/area.hpp"

namespace plcemu::engine {

/// A word of a loop that a person may change from its faceplate.
struct LoopParameter {
    std::string name;      ///< "Kc", "TI"
    image::Device device;  ///< where it is
    std::string unit;      ///< "0.01 repeats/min", "100 ms"
};

/// A bit of a word that signals something about the loop.
struct LoopFlag {
    std::string name;      ///< "in zone", "heater open"
    image::Device word;    ///< the word that holds it (or the bit itself: a bit device)
    std::uint8_t bit = 0;  ///< which bit of the word
};

/// One loop.
struct Loop {
    std::string name;                 ///< "TPCTL point 3 (channel 3)", "PID D100"
    int channel = -1;                 ///< the plant channel it measures (-1: none known)
    std::optional<image::Device> pv;  ///< the process value (none while it has no source)
    image::Device sv;                 ///< the set point
    image::Device output;             ///< the output the loop computes
    double scale = 1;                 ///< PV and SV: engineering units per count (0.1 °C: 0.1)
    std::string unit;                 ///< their unit ("°C"; "" for counts)
    double output_full = 100;         ///< the output's value at 100 %
    std::vector<LoopParameter> parameters;  ///< set point aside, what may be tuned
    std::vector<LoopFlag> alarms;           ///< warnings and alarms
    std::optional<LoopFlag> manual;         ///< on: the output is the operator's
    std::optional<LoopFlag> tuning;         ///< set to start auto-tuning; on while it runs
};

/// The loops of a program, in program order.
using Loops = std::vector<Loop>;

}  // namespace plcemu::engine
