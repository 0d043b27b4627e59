#include "pls.hpp"

#include "edge.hpp"
#include "operands.hpp"

namespace plcemu::instructions {

namespace {

template <class Edge>
class Pulse final : public engine::Instruction {
public:
    Pulse(BitSource en, image::Device d, std::string_view mnemonic)
        : en_(en),
          d_(d),
          mnemonic_(mnemonic) {}

    void execute(engine::ScanContext& ctx) noexcept override {
        ctx.image.write_bit(d_, edge_(en_.read(ctx.image), ctx.first_scan));
    }

    std::string_view mnemonic() const noexcept override { return mnemonic_; }

private:
    BitSource en_;
    image::Device d_;
    std::string_view mnemonic_;
    Edge edge_;
};

template <class Edge>
std::unique_ptr<engine::Instruction> make(const Entry& ic,
                                          const BindContext& ctx,
                                          std::string_view mnemonic) {
    Operands ops(ic, ctx);
    const BitSource en = ops.bit_source("en", true);
    const image::Device d = ops.bit_output("d");
    ops.finish();
    return std::make_unique<Pulse<Edge>>(en, d, mnemonic);
}

}  // namespace

std::unique_ptr<engine::Instruction> make_pls(const Entry& ic, const BindContext& ctx) {
    return make<RisingEdge>(ic, ctx, "PLS");
}

std::unique_ptr<engine::Instruction> make_plf(const Entry& ic, const BindContext& ctx) {
    return make<FallingEdge>(ic, ctx, "PLF");
}

}  // namespace plcemu::instructions
