#include "wor.hpp"

#include "operands.hpp"

namespace plcemu::instructions {

namespace {

class Wor final : public engine::Instruction {
public:
    Wor(BitSource en, WordSource s1, WordSource s2, image::Device d)
        : en_(en),
          s1_(s1),
          s2_(s2),
          d_(d) {}

    void execute(engine::ScanContext& ctx) noexcept override {
        if (!en_.read(ctx.image)) return;
        const auto v = static_cast<std::uint16_t>(s1_.read(ctx.image) | s2_.read(ctx.image));
        ctx.image.write_word(d_, v);
    }

    std::string_view mnemonic() const noexcept override { return "WOR"; }

private:
    BitSource en_;
    WordSource s1_;
    WordSource s2_;
    image::Device d_;
};

}  // namespace

std::unique_ptr<engine::Instruction> make_wor(const Entry& ic, const BindContext& ctx) {
    Operands ops(ic, ctx);
    const BitSource en = ops.bit_source("en", true);
    const WordSource s1 = ops.word_source("s1");
    const WordSource s2 = ops.word_source("s2");
    const image::Device d = ops.word_output("d");
    ops.finish();
    return std::make_unique<Wor>(en, s1, s2, d);
}

}  // namespace plcemu::instructions
