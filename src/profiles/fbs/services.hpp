#pragma once
// What the FBs profile offers its instructions while they bind.

#include <optional>

#include "plcemu/image/area.hpp"
#include "plcemu/instructions/instructions.hpp"
#include "instructions/cnt.hpp"
#include "instructions/tmr.hpp"

namespace plcemu::profiles::fbs {

/// The FBs services: the generic ones plus the temperature configuration table TPCTL reads.
struct Services : instructions::TimerServices, instructions::CounterServices {
    std::optional<image::Device> temperature_table;  ///< `temperature.table`, when set
};

}  // namespace plcemu::profiles::fbs
