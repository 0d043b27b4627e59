#include "cmpout.hpp"

#include <array>
#include <cstdint>
#include <string_view>

#include "operands.hpp"
#include "plcemu/image/excerpt.hpp"

namespace plcemu::instructions {

namespace {

enum class Op : std::uint8_t { Eq, Ne, Lt, Le, Gt, Ge };

// The operators as the manuals write them.
constexpr std::array<std::pair<std::string_view, Op>, 6> kOps{
    {{"=", Op::Eq}, {"<>", Op::Ne}, {"<", Op::Lt}, {"<=", Op::Le}, {">", Op::Gt}, {">=", Op::Ge}}};

bool compare(Op op, std::int16_t a, std::int16_t b) noexcept {
    switch (op) {
        case Op::Eq:
            return a == b;
        case Op::Ne:
            return a != b;
        case Op::Lt:
            return a < b;
        case Op::Le:
            return a <= b;
        case Op::Gt:
            return a > b;
        case Op::Ge:
            return a >= b;
    }
    return false;
}

class CmpOut final : public engine::Instruction {
public:
    CmpOut(Op op, WordSource s1, WordSource s2, image::Device out)
        : op_(op),
          s1_(s1),
          s2_(s2),
          out_(out) {}

    void execute(engine::ScanContext& ctx) noexcept override {
        const auto a = static_cast<std::int16_t>(s1_.read(ctx.image));
        const auto b = static_cast<std::int16_t>(s2_.read(ctx.image));
        ctx.image.write_bit(out_, compare(op_, a, b));
    }

    std::string_view mnemonic() const noexcept override { return "CMPOUT"; }

private:
    Op op_;
    WordSource s1_;
    WordSource s2_;
    image::Device out_;
};

}  // namespace

std::unique_ptr<engine::Instruction> make_cmpout(const Entry& ic, const BindContext& ctx) {
    Operands ops(ic, ctx);
    const std::string& text = ops.text("op");
    Op op = Op::Eq;
    bool known = false;
    for (const auto& [name, o] : kOps) {
        if (text == name) {
            op = o;
            known = true;
        }
    }
    if (!known)
        ops.fail("op", "expected one of = <> < <= > >=, got '" + image::excerpt(text) + "'");
    const WordSource s1 = ops.word_source("s1");
    const WordSource s2 = ops.word_source("s2");
    const image::Device out = ops.bit_output("out");
    ops.finish();
    return std::make_unique<CmpOut>(op, s1, s2, out);
}

}  // namespace plcemu::instructions
