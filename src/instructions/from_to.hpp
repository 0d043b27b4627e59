#pragma once
// FROM and TO: reading and writing the buffer memory of a special module (VB manual FNC88 and
// FNC92 examples: `FROM K1 K32 D0 K8`, `TOP K1 K0 K7 K8`). The two are one transfer in opposite
// directions, so they share this file.

#include <memory>

#include "plcemu/engine/engine.hpp"
#include "plcemu/instructions/instructions.hpp"

namespace plcemu::instructions {

/// `FROM: {en: M9000, m1: 1, m2: 32, d: D0, n: 8, p: false}`: while EN is ON (with `p: true`,
/// at its rising edge only), buffer words m2…m2+n−1 of module m1 are copied to D…D+n−1.
std::unique_ptr<engine::Instruction> make_from(const Entry& ic, const BindContext& ctx);

/// `TO: {en: M9002, m1: 1, m2: 0, s: 7, n: 8, p: true}`: the other way, S…S+n−1 into the
/// module's words m2…; a constant S is written to all n words.
std::unique_ptr<engine::Instruction> make_to(const Entry& ic, const BindContext& ctx);

}  // namespace plcemu::instructions
