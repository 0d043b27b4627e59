#pragma once
// FNC149 MBUS, the VB as a Modbus master cycling through a communication table (VB manual
// FNC149, "MODBUS Communication"; docs/profile-vb.md, "FNC149 MBUS").

#include <memory>

#include "plcemu/engine/engine.hpp"
#include "plcemu/instructions/instructions.hpp"

namespace plcemu::profiles::vb {

/// `MBUS: {en: X20, s1: D1000, s2: D100}`: while EN is ON, the transfer sets of the table at S1
/// (S1+0 sets of 7 words from S1+1) are sent one at a time through the engine's outbound link,
/// S2+0 holds the status and the station of the last failed transfer, S2+1 the set in
/// progress, S2+2 the completed passes, S2+3 the last exception code, and M9199 is ON for one
/// scan after each pass. A program may have one MBUS only.
std::unique_ptr<engine::Instruction> make_mbus(const instructions::Entry& ic,
                                               const instructions::BindContext& ctx);

}  // namespace plcemu::profiles::vb
