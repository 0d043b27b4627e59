#include "cmpout.hpp"

#include <cstdint>

#include "operands.hpp"
#include "relation.hpp"
#include "plcemu/image/excerpt.hpp"

namespace plcemu::instructions {

namespace {

class CmpOut final : public engine::Instruction {
public:
    CmpOut(Relation op, WordSource s1, WordSource s2, image::Device out)
        : op_(op),
          s1_(s1),
          s2_(s2),
          out_(out) {}

    void execute(engine::ScanContext& ctx) noexcept override {
        const auto a = static_cast<std::int16_t>(s1_.read(ctx.image));
        const auto b = static_cast<std::int16_t>(s2_.read(ctx.image));
        ctx.image.write_bit(out_, holds(op_, a, b));
    }

    std::string_view mnemonic() const noexcept override { return "CMPOUT"; }

private:
    Relation op_;
    WordSource s1_;
    WordSource s2_;
    image::Device out_;
};

}  // namespace

std::unique_ptr<engine::Instruction> make_cmpout(const Entry& ic, const BindContext& ctx) {
    Operands ops(ic, ctx);
    const std::string& text = ops.text("op");
    const auto op = relation_of(text);
    if (!op) ops.fail("op", "expected one of = <> < <= > >=, got '" + image::excerpt(text) + "'");
    const WordSource s1 = ops.word_source("s1");
    const WordSource s2 = ops.word_source("s2");
    const image::Device out = ops.bit_output("out");
    ops.finish();
    return std::make_unique<CmpOut>(*op, s1, s2, out);
}

}  // namespace plcemu::instructions
