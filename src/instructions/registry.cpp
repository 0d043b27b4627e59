// Mnemonic → builder. Adding an instruction: one file with its make_ function, one row here.

#include <map>
#include <string>

#include "mov.hpp"
#include "tpctl.hpp"
#include "plcemu/instructions/instructions.hpp"

namespace plcemu::instructions {

namespace {

using Builder = std::unique_ptr<engine::Instruction> (*)(const config::InstructionConfig&,
                                                         const BindContext&);

const std::map<std::string, Builder>& builders() {
    static const std::map<std::string, Builder> kBuilders{
        {"MOV", &make_mov},
        {"TPCTL", &make_tpctl},
    };
    return kBuilders;
}

}  // namespace

std::unique_ptr<engine::Instruction> make_instruction(const config::InstructionConfig& ic,
                                                      const BindContext& ctx) {
    const auto& b = builders();
    auto it = b.find(ic.mnemonic);
    if (it == b.end()) {
        std::string names;
        for (const auto& [k, v] : b) names += std::string(names.empty() ? "" : ", ") + k;
        throw config::ConfigError(ic.pos, "unknown instruction '" + config::excerpt(ic.mnemonic) +
                                              "' (this profile knows: " + names + ")");
    }
    return it->second(ic, ctx);
}

engine::Program make_program(const config::Config& config, const image::Layout& layout) {
    engine::Program p;
    const BindContext ctx{layout, config};
    for (const auto& ic : config.program) p.push_back(make_instruction(ic, ctx));
    return p;
}

}  // namespace plcemu::instructions
