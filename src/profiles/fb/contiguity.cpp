#include "profiles/fb/contiguity.hpp"

namespace plcemu::profiles::fb {

void Contiguity::check(instructions::Operands& ops,
                       const Module& tp4,
                       const Run& tstc,
                       bool at_tstc) {
    const ModuleOperands& a = tp4.m;
    const ModuleOperands& b = tstc.m;
    if (a.sm == b.sm) return;  // its own module: refused elsewhere (two on one module)
    const long long first = a.sm;
    const long long last = a.sm + cycle::kPoints - 1;
    if (last < tstc.sh || first > tstc.sh + tstc.zh - 1) return;  // none of its points
    const std::string other = at_tstc ? "the TP4 at " + tp4.where : "the TSTC at " + tstc.where;
    const std::string points = "points " + std::to_string(first) + "-" + std::to_string(last) +
                               " (measured by the TP4 at " + tp4.where +
                               ", controlled by the TSTC at " + tstc.where + ")";
    if (a.tp != b.tp || a.pl != b.pl) {
        ops.fail(a.tp != b.tp ? "tp" : "pl",
                 "tp " + std::to_string(a.tp) + ", pl " + std::to_string(a.pl) + " against tp " +
                     std::to_string(b.tp) + ", pl " + std::to_string(b.pl) + ": " + points +
                     " need modules of one type with the same range and polarity");
    }
    image::Device expected = b.tr;
    expected.index += static_cast<std::uint32_t>(a.sm - b.sm);
    if (a.tr.area != expected.area || a.tr.index != expected.index) {
        const image::Range want{expected.area, expected.index, cycle::kPoints};
        ops.fail("tr", "the readings of " + points + " must be at " + ops.format(want) +
                           ", TR + (point - Sm) of " + (at_tstc ? "this TSTC" : other) +
                           " (TR must be contiguous)");
    }
}

void Contiguity::measured(instructions::Operands& ops,
                          const ModuleOperands& m,
                          const std::string& where) {
    const Module tp4{m, where};
    for (const Run& r : runs_) check(ops, tp4, r, false);
    modules_.push_back(tp4);
}

void Contiguity::controlled(instructions::Operands& ops,
                            const ModuleOperands& m,
                            long long sh,
                            long long zh,
                            const std::string& where) {
    const Run run{m, sh, zh, where};
    for (const Module& tp4 : modules_) check(ops, tp4, run, true);
    runs_.push_back(run);
}

}  // namespace plcemu::profiles::fb
