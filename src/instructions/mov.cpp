#include "mov.hpp"

#include "edge.hpp"
#include "operands.hpp"

namespace plcemu::instructions {

namespace {

class Mov final : public engine::Instruction {
public:
    Mov(BitSource en, bool pulse, WordSource s, image::Device d)
        : en_(en),
          pulse_(pulse),
          s_(s),
          d_(d) {}

    void execute(engine::ScanContext& ctx) noexcept override {
        const bool on = en_.read(ctx.image);
        // The edge is tracked in every scan, so a pulse form sees each OFF→ON once.
        const bool edge = edge_(on, ctx.first_scan);
        if (pulse_ ? edge : on) ctx.image.write_word(d_, s_.read(ctx.image));
    }

    std::string_view mnemonic() const noexcept override { return pulse_ ? "MOVP" : "MOV"; }

private:
    BitSource en_;
    bool pulse_;
    WordSource s_;
    image::Device d_;
    RisingEdge edge_;
};

}  // namespace

std::unique_ptr<engine::Instruction> make_mov(const Entry& ic, const BindContext& ctx) {
    Operands ops(ic, ctx);
    const BitSource en = ops.bit_source("en", true);
    const bool pulse = ops.flag("p", false);
    const WordSource s = ops.word_source("s");
    const image::Device d = ops.word_output("d");
    ops.finish();
    return std::make_unique<Mov>(en, pulse, s, d);
}

}  // namespace plcemu::instructions
