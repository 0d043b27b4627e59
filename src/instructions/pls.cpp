#include "pls.hpp"

#include "edge.hpp"
#include "operands.hpp"

namespace plcemu::instructions {

namespace {

class Pls final : public engine::Instruction {
public:
    Pls(BitSource en, image::Device d)
        : en_(en),
          d_(d) {}

    void execute(engine::ScanContext& ctx) noexcept override {
        ctx.image.write_bit(d_, edge_(en_.read(ctx.image)));
    }

    std::string_view mnemonic() const noexcept override { return "PLS"; }

private:
    BitSource en_;
    image::Device d_;
    RisingEdge edge_;
};

}  // namespace

std::unique_ptr<engine::Instruction> make_pls(const Entry& ic, const BindContext& ctx) {
    Operands ops(ic, ctx);
    const BitSource en = ops.bit_source("en", true);
    const image::Device d = ops.bit_output("d");
    ops.finish();
    return std::make_unique<Pls>(en, d);
}

}  // namespace plcemu::instructions
