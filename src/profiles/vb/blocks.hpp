#pragma once
// The register blocks of the VB's own instructions (FNC92 TPID's S1–S4, FNC149 MBUS's table and
// working area): D registers that must all lie in D0–D7999, the manual's D range.

#include <cstdint>
#include <string>

#include "instructions/operands.hpp"

namespace plcemu::profiles::vb {

/// Where D registers a block may use end: D7999 (D9000–D9255 are special registers).
inline constexpr std::uint32_t kBlockAreaEnd = 8000;

/// Whether the instruction writes the block.
enum class Use : std::uint8_t { Read, Written };

/// The first register of a block of `span` D registers named `name` at operand `key`. A block
/// the instruction writes may not hold registers the profile reserves (file registers).
inline std::uint32_t d_block(
    instructions::Operands& ops, const char* key, const char* name, std::uint32_t span, Use use) {
    const image::Device d = ops.word_device(key, 1, {image::Area::D});
    const image::Range r{image::Area::D, d.index, span};
    if (d.index + span > kBlockAreaEnd) {
        ops.fail(key, std::string(name) + " needs " + std::to_string(span) + " registers, " +
                          ops.format(r) + ", inside D0-D7999");
    }
    if (use == Use::Written) ops.refuse_reserved(key, r);
    return d.index;
}

}  // namespace plcemu::profiles::vb
