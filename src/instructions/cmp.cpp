#include "cmp.hpp"

#include <cstdint>

#include "edge.hpp"
#include "operands.hpp"

namespace plcemu::instructions {

namespace {

using image::Area;

class Cmp final : public engine::Instruction {
public:
    Cmp(BitSource en, WordSource s1, WordSource s2, image::Device d, bool pulse)
        : en_(en),
          s1_(s1),
          s2_(s2),
          d_(d),
          pulse_(pulse) {}

    void execute(engine::ScanContext& ctx) noexcept override {
        const bool on = en_.read(ctx.image);
        if (!(pulse_ ? edge_(on, ctx.first_scan) : on)) return;
        const auto a = static_cast<std::int16_t>(s1_.read(ctx.image));
        const auto b = static_cast<std::int16_t>(s2_.read(ctx.image));
        image::Device d = d_;
        ctx.image.write_bit(d, a > b);
        ++d.index;
        ctx.image.write_bit(d, a == b);
        ++d.index;
        ctx.image.write_bit(d, a < b);
    }

    std::string_view mnemonic() const noexcept override { return "CMP"; }

private:
    BitSource en_;
    WordSource s1_;
    WordSource s2_;
    image::Device d_;
    bool pulse_;
    RisingEdge edge_;
};

}  // namespace

std::unique_ptr<engine::Instruction> make_cmp(const Entry& ic, const BindContext& ctx) {
    Operands ops(ic, ctx);
    const BitSource en = ops.bit_source("en", true);
    const WordSource s1 = ops.word_source("s1");
    const WordSource s2 = ops.word_source("s2");
    const image::Device d = ops.device("d", 3, {Area::Y, Area::M, Area::S});
    ops.refuse_reserved("d", {d.area, d.index, 3});
    const bool pulse = ops.flag("p", false);
    ops.finish();
    return std::make_unique<Cmp>(en, s1, s2, d, pulse);
}

}  // namespace plcemu::instructions
