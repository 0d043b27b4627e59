#pragma once
// Building program instructions from their config entries.

#include <memory>

#include "plcemu/config/config.hpp"
#include "plcemu/engine/engine.hpp"
#include "plcemu/image/layout.hpp"

namespace plcemu::instructions {

/// What an instruction may look at while it binds its operands.
struct BindContext {
    const image::Layout& layout;   ///< device limits
    const config::Config& config;  ///< the whole config (e.g. the temperature table start)
};

/// Builds one instruction; throws config::ConfigError (with the operand's position) when the
/// mnemonic is unknown or an operand is invalid.
std::unique_ptr<engine::Instruction> make_instruction(const config::InstructionConfig& ic,
                                                      const BindContext& ctx);

/// Builds the whole `program:` list.
engine::Program make_program(const config::Config& config, const image::Layout& layout);

}  // namespace plcemu::instructions
