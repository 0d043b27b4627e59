#include "profiles/fatek/operands.hpp"

#include <string>

namespace plcemu::profiles::fatek {

namespace {

using image::Area;

// HR R0–R3839 and ROR R5000–R8071 (FBs manual §21.7, FB manual FUN73 operand tables).
constexpr std::uint32_t kHrEnd = 3840;
constexpr std::uint32_t kRorStart = 5000;

}  // namespace

image::Device register_block(instructions::Operands& ops, const char* key, std::uint32_t span) {
    const image::Device d = ops.word_device(key, span, {Area::R, Area::D});
    const bool ok = d.area == Area::D || d.index + span <= kHrEnd || d.index >= kRorStart;
    if (!ok) {
        const std::uint32_t d_size = ops.context().layout.size_of(Area::D);
        ops.fail(key, "expected " + std::to_string(span) + " register(s) in R0-R3839, " +
                          "R5000-R8071 or " + ops.format({Area::D, 0, d_size}) + ", got " +
                          ops.format({d.area, d.index, span}));
    }
    return d;
}

void bind_point_blocks(instructions::Operands& ops, std::uint32_t span, LoopBlocks& into) {
    into.sv = register_block(ops, "sv", span);
    into.os = register_block(ops, "os", span);
    into.pr = register_block(ops, "pr", span);
    into.ir = register_block(ops, "ir", span);
    into.dr = register_block(ops, "dr", span);
    into.out = register_block(ops, "or", span);
}

}  // namespace plcemu::profiles::fatek
