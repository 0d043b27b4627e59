#include "profiles/fb/program_checks.hpp"

#include <optional>
#include <string>

#include "plcemu/config/reader.hpp"
#include "profiles/fb/temperature_config.hpp"

namespace plcemu::profiles::fb {

void check_temperature_program(const std::vector<ProgramInstruction>& program) {
    const ProgramInstruction* slim = nullptr;   // the first TP4 or TSTC
    const ProgramInstruction* tpsns = nullptr;  // the first TPSNS
    const ProgramInstruction* tpctl = nullptr;  // the first TPCTL
    for (const auto& e : program) {
        const bool measures_slim = e.mnemonic == "TP4" || e.mnemonic == "TSTC";
        if (e.mnemonic == "TPSNS" && tpsns != nullptr) {
            throw config::ConfigError(
                e.pos,
                "a second TPSNS: a program has at most one (one FB-4AJ(K)xx), the first is "
                "at " +
                    position_text(tpsns->pos));
        }
        // FB manual FUN73: the FB-2A…4 "cannot be used together with … FB-4AJ(K)xx".
        const ProgramInstruction* other =
            measures_slim ? tpsns : (e.mnemonic == "TPSNS" ? slim : nullptr);
        if (other != nullptr) {
            throw config::ConfigError(
                e.pos, "the " + e.mnemonic + " cannot be used with the " + other->mnemonic +
                           " at " + position_text(other->pos) +
                           " (TPSNS measures an FB-4AJ(K)xx, which is used alone, without the "
                           "FB-2A…4 modules of TP4 and TSTC)");
        }
        if (measures_slim && slim == nullptr) slim = &e;
        if (e.mnemonic == "TPSNS") tpsns = &e;
        if (e.mnemonic == "TPCTL" && tpctl == nullptr) tpctl = &e;
    }
    // FB manual FUN86: "FUN86 must incorporate with FUN85 when using."
    if (tpctl != nullptr && tpsns == nullptr) {
        throw config::ConfigError(tpctl->pos,
                                  "TPCTL needs a TPSNS in the program: in profile fb it controls "
                                  "the points FUN85 TPSNS measures");
    }
}

}  // namespace plcemu::profiles::fb
