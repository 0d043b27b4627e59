#pragma once
// The devices the FB temperature instructions write and read, checked across the program at
// load: two instructions may not write the same devices, nor one write what another reads as its
// settings (FB manual FUN73/FUN86: WR "can't be repeated in using"; docs/profile-fb.md, the
// "Checks at load" of TP4, TSTC, TPSNS and TPCTL).

#include <optional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "instructions/operands.hpp"
#include "plcemu/image/image.hpp"
#include "plcemu/engine/declarations.hpp"

namespace plcemu::profiles::fb {

/// Adds to `mine`, under `key`, the one bit `bit` (an optional ERR/ALM-like output) as written.
void claim_bit(std::vector<std::pair<const char*, engine::Claim>>& mine,
               const char* key,
               const std::optional<image::Device>& bit,
               std::string_view mnemonic,
               const std::string& where);

/// Refuses, at the operand of the later entry and naming the earlier one, `mine` (this
/// instruction's claims, each with the operand key that names it) overlapping each other or the
/// claims of the entries before it — unless both claims are ClaimKind::Read: settings may be
/// shared, but no claim may write into another's settings. Returns the claims, for the
/// instruction to declare.
std::vector<engine::Claim> refuse_shared(
    instructions::Operands& ops, const std::vector<std::pair<const char*, engine::Claim>>& mine);

/// Writes `v` to `bit` when the instruction has that optional output (ERR, ALM, AO0, AO1).
inline void write_optional(image::Image& img, const std::optional<image::Device>& bit, bool v) {
    if (bit) img.write_bit(*bit, v);
}

}  // namespace plcemu::profiles::fb
