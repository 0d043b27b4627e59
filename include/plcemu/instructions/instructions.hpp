#pragma once
// Building program instructions from their config entries: an instruction table maps mnemonics
// to builders (each profile has its own), and a builder gets the operands and the services it
// needs, never the whole config.

#include <functional>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "plcemu/config/config.hpp"
#include "plcemu/engine/engine.hpp"
#include "plcemu/image/layout.hpp"
#include "plcemu/image/naming.hpp"

namespace plcemu::instructions {

/// What a profile offers its instructions while they bind. A profile with more to offer derives
/// from it (its own instructions know the derived type).
struct Services {
    virtual ~Services() = default;
    /// Outputs the program may not drive, each with the reason an error gives.
    std::vector<std::pair<image::Range, std::string>> reserved_outputs;
};

/// What an instruction may look at while it binds its operands.
struct BindContext {
    const image::Layout& layout;     ///< device limits
    const image::Naming& naming;     ///< how devices and constants are written
    const Services& services;        ///< the profile's services
    const engine::Program& earlier;  ///< the entries bound before this one (their declarations)
};

/// Builds one instruction; throws config::ConfigError (with the operand's position).
using Builder = std::unique_ptr<engine::Instruction> (*)(const config::InstructionConfig&,
                                                         const BindContext&);
/// Mnemonic → builder.
using Table = std::map<std::string, Builder, std::less<>>;

/// Builds the whole program with `table`; an unknown mnemonic is an error naming the ones the
/// table knows.
engine::Program make_program(const std::vector<config::InstructionConfig>& program,
                             const Table& table,
                             const image::Layout& layout,
                             const image::Naming& naming,
                             const Services& services);

}  // namespace plcemu::instructions
