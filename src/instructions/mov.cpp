#include "mov.hpp"

#include "operands.hpp"

namespace plcemu::instructions {

namespace {

class Mov final : public engine::Instruction {
public:
    Mov(BitSource en, WordSource s, image::Device d)
        : en_(en),
          s_(s),
          d_(d) {}

    void execute(engine::ScanContext& ctx) noexcept override {
        if (en_.read(ctx.image)) ctx.image.write_word(d_, s_.read(ctx.image));
    }

    std::string_view mnemonic() const noexcept override { return "MOV"; }

private:
    BitSource en_;
    WordSource s_;
    image::Device d_;
};

}  // namespace

std::unique_ptr<engine::Instruction> make_mov(const Entry& ic, const BindContext& ctx) {
    Operands ops(ic, ctx);
    const BitSource en = ops.bit_source("en", true);
    const WordSource s = ops.word_source("s");
    const image::Device d =
        ops.word_device("d", 1,
                        {image::Area::R, image::Area::D, image::Area::M, image::Area::Y,
                         image::Area::S, image::Area::TV, image::Area::CV});
    ops.finish();
    if (d.word_of_bits) ops.refuse_reserved("d", {d.area, d.index, 16});
    return std::make_unique<Mov>(en, s, d);
}

}  // namespace plcemu::instructions
