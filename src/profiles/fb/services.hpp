#pragma once
// What the FB profile offers its instructions while they bind: the temperature points they
// share, the modules `temperature.modules` declares, and what the entries bound so far tell the
// later ones (the contiguous TRs, the controlled points, the TPSNS).

#include <memory>
#include <vector>

#include "plcemu/instructions/instructions.hpp"
#include "instructions/cnt.hpp"
#include "instructions/tmr.hpp"
#include "profiles/fb/contiguity.hpp"
#include "profiles/fb/controlled_points.hpp"
#include "profiles/fb/points.hpp"
#include "profiles/fb/temperature_config.hpp"
#include "profiles/fb/tpsns_link.hpp"

namespace plcemu::profiles::fb {

/// The FB services: the generic ones, the points 0–31 every measuring and controlling
/// instruction of the program shares, and the chain of modules (empty: what the program says).
struct Services : instructions::TimerServices, instructions::CounterServices {
    std::shared_ptr<Points> points = std::make_shared<Points>();  ///< shared by the program
    std::vector<TemperatureModule> modules;                       ///< `temperature.modules`
    /// The TP4s and TSTCs bound so far, for the contiguous-TR rule.
    std::shared_ptr<Contiguity> contiguity = std::make_shared<Contiguity>();
    /// The TSTCs and TPCTLs bound so far: one controller per point.
    std::shared_ptr<ControlledPoints> controlled = std::make_shared<ControlledPoints>();
    /// The program's TPSNS (at most one), for its TPCTLs.
    std::shared_ptr<TpsnsLink> tpsns = std::make_shared<TpsnsLink>();
};

}  // namespace plcemu::profiles::fb
