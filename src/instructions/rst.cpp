#include "rst.hpp"

#include "operands.hpp"

namespace plcemu::instructions {

namespace {

using image::Area;

class Rst final : public engine::Instruction {
public:
    /// `bit`: the contact or relay to clear, if any; `words`: the value words to clear.
    Rst(BitSource en, std::optional<image::Device> bit, image::Range words)
        : en_(en),
          bit_(bit),
          words_(words) {}

    void execute(engine::ScanContext& ctx) noexcept override {
        if (!en_.read(ctx.image)) return;
        if (bit_) ctx.image.write_bit(*bit_, false);
        for (std::uint32_t i = words_.start; i < words_.end(); ++i) {
            ctx.image.set_word(words_.area, i, 0);
        }
    }

    std::string_view mnemonic() const noexcept override { return "RST"; }

private:
    BitSource en_;
    std::optional<image::Device> bit_;
    image::Range words_;
};

}  // namespace

std::unique_ptr<engine::Instruction> make_rst(const Entry& ic, const BindContext& ctx) {
    Operands ops(ic, ctx);
    const BitSource en = ops.bit_source("en", true);
    const image::Device d =
        ops.device("d", 1, {Area::Y, Area::M, Area::S, Area::T, Area::C, Area::R, Area::D});
    ops.finish();
    std::optional<image::Device> bit;
    image::Range words{Area::D, 0, 0};
    if (d.area == Area::T) {
        bit = d;
        words = {Area::TV, d.index, 1};
    } else if (d.area == Area::C) {
        bit = d;
        words = {Area::CV, ctx.naming.counter_word(d.index), ctx.naming.counter_words(d.index)};
    } else if (image::is_bit_area(d.area)) {
        bit = d;
        ops.refuse_reserved("d", {d.area, d.index, 1});
    } else {
        words = {d.area, d.index, 1};
        ops.refuse_reserved("d", words);
    }
    if (words.count > 0 && !ctx.layout.contains(words)) {
        ops.fail("d", ctx.naming.format_device(d.area, d.index) + " has no value in this PLC");
    }
    return std::make_unique<Rst>(en, bit, words);
}

}  // namespace plcemu::instructions
