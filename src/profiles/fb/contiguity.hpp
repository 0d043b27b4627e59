#pragma once
// FB manual FUN73: "TR must be contiguous, starting at the first point of modules of the same
// type", and the modules "of one type with the same range and polarity". A TSTC controlling
// points outside its own module takes their PVs at TR + (p − Sm), so the TP4 measuring such a
// point must have the TSTC's Tp and Pl and put its readings exactly there. Checked at load, at
// whichever of the two entries comes later (docs/profile-fb.md, "FUN73 TSTC").

#include <string>
#include <vector>

#include "instructions/operands.hpp"
#include "profiles/fb/module_cycle.hpp"

namespace plcemu::profiles::fb {

/// What the program's measuring and controlling entries bound so far.
class Contiguity {
public:
    /// A TP4 on module `m`: refused at `ops` if an earlier TSTC controls one of its points with
    /// another Tp or Pl or another TR.
    void measured(instructions::Operands& ops, const ModuleOperands& m, const std::string& where);
    /// A TSTC on module `m` controlling points sh…sh+zh−1: refused at `ops` if an earlier TP4
    /// measures one of them with another Tp or Pl or another TR.
    void controlled(instructions::Operands& ops,
                    const ModuleOperands& m,
                    long long sh,
                    long long zh,
                    const std::string& where);

private:
    struct Module {
        ModuleOperands m;
        std::string where;
    };
    struct Run {
        ModuleOperands m;
        long long sh = 0, zh = 0;
        std::string where;
    };
    static void check(instructions::Operands& ops,
                      const Module& tp4,
                      const Run& tstc,
                      bool at_tstc);

    std::vector<Module> modules_;
    std::vector<Run> runs_;
};

}  // namespace plcemu::profiles::fb
