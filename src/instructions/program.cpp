// A program from its config entries, through a profile's instruction table.

#include <string>

#include "plcemu/instructions/instructions.hpp"

namespace plcemu::instructions {

engine::Program make_program(const std::vector<config::InstructionConfig>& program,
                             const Table& table,
                             const image::Layout& layout,
                             const image::Naming& naming,
                             const Services& services) {
    engine::Program p;
    p.reserve(program.size());
    for (const auto& ic : program) {
        const auto it = table.find(ic.mnemonic);
        if (it == table.end()) {
            std::string names;
            for (const auto& [k, v] : table) names += std::string(names.empty() ? "" : ", ") + k;
            throw config::ConfigError(ic.pos, "unknown instruction '" +
                                                  config::excerpt(ic.mnemonic) +
                                                  "' (this profile knows: " + names + ")");
        }
        const BindContext ctx{layout, naming, services, p};
        p.push_back(it->second(ic, ctx));
    }
    return p;
}

}  // namespace plcemu::instructions
