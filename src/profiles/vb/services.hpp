#pragma once
// What the VB profile offers its instructions while they bind: CNT's direction relays and
// TMR's time bases.

#include "instructions/cnt.hpp"
#include "instructions/tmr.hpp"

namespace plcemu::profiles::vb {

/// The VB services.
struct Services final : instructions::CounterServices, instructions::TimerServices {};

}  // namespace plcemu::profiles::vb
