#include "rst.hpp"

#include "edge.hpp"
#include "operands.hpp"

namespace plcemu::instructions {

namespace {

using image::Area;

// RST clears one device; ZRST a zone of them. Both clear contacts or relays (`bits`) and values
// (`words`).
class Rst final : public engine::Instruction {
public:
    Rst(BitSource en, image::Range bits, image::Range words, std::string_view mnemonic, bool pulse)
        : en_(en),
          bits_(bits),
          words_(words),
          mnemonic_(mnemonic),
          pulse_(pulse) {}

    void execute(engine::ScanContext& ctx) noexcept override {
        const bool on = en_.read(ctx.image);
        if (!(pulse_ ? edge_(on, ctx.first_scan) : on)) return;
        for (std::uint32_t i = bits_.start; i < bits_.end(); ++i) {
            ctx.image.write_bit({bits_.area, i}, false);
        }
        for (std::uint32_t i = words_.start; i < words_.end(); ++i) {
            ctx.image.set_word(words_.area, i, 0);
        }
    }

    std::string_view mnemonic() const noexcept override { return mnemonic_; }

private:
    BitSource en_;
    image::Range bits_;
    image::Range words_;
    std::string_view mnemonic_;
    bool pulse_;
    RisingEdge edge_;
};

struct Zone {
    image::Range bits{Area::M, 0, 0};
    image::Range words{Area::D, 0, 0};
};

// What clearing `first` … `last` (one area) clears.
Zone zone_of(Operands& ops,
             const char* key,
             const BindContext& ctx,
             const image::Device& first,
             const image::Device& last) {
    const std::uint32_t n = last.index - first.index + 1;
    Zone z;
    if (first.area == Area::T) {
        z.bits = {Area::T, first.index, n};
        z.words = {Area::TV, first.index, n};
    } else if (first.area == Area::C) {
        z.bits = {Area::C, first.index, n};
        const std::uint32_t from = ctx.naming.counter_word(first.index);
        z.words = {
            Area::CV, from,
            ctx.naming.counter_word(last.index) + ctx.naming.counter_words(last.index) - from};
    } else if (image::is_bit_area(first.area)) {
        z.bits = {first.area, first.index, n};
        ops.refuse_reserved(key, z.bits);
    } else {
        z.words = {first.area, first.index, n};
        ops.refuse_reserved(key, z.words);
    }
    // A zone through numbers no device has (M3072-M8999 between a VB's M3071 and its special
    // relays at M9000, D8000-D8999) would clear what lies beyond them: refused, naming them.
    for (const image::Range& r : {z.bits, z.words}) {
        for (const image::Range& h : ctx.layout.holes) {
            if (r.count > 0 && h.overlaps(r)) {
                ops.fail(key, ctx.naming.format_range({first.area, first.index, n}) +
                                  " runs through " + ctx.naming.format_range(h) +
                                  ", which this PLC does not have");
            }
        }
    }
    if (z.words.count > 0 && !ctx.layout.contains(z.words)) {
        ops.fail(key,
                 ctx.naming.format_device(first.area, first.index) + " has no value in this PLC");
    }
    return z;
}

constexpr std::initializer_list<Area> kResettable = {Area::Y, Area::M, Area::S, Area::T,
                                                     Area::C, Area::R, Area::D};

}  // namespace

std::unique_ptr<engine::Instruction> make_rst(const Entry& ic, const BindContext& ctx) {
    Operands ops(ic, ctx);
    const BitSource en = ops.bit_source("en", true);
    const image::Device d = ops.device("d", 1, kResettable);
    const bool pulse = ops.flag("p", false);  // FATEK's RST P
    ops.finish();
    const Zone z = zone_of(ops, "d", ctx, d, d);
    return std::make_unique<Rst>(en, z.bits, z.words, "RST", pulse);
}

std::unique_ptr<engine::Instruction> make_zrst(const Entry& ic, const BindContext& ctx) {
    Operands ops(ic, ctx);
    const BitSource en = ops.bit_source("en", true);
    const image::Device d1 = ops.device("d1", 1, kResettable);
    const image::Device d2 = ops.device("d2", 1, kResettable);
    const bool pulse = ops.flag("p", false);
    ops.finish();
    // FX manual FNC40: D1 and D2 are devices of one kind, D1 not above D2.
    if (d2.area != d1.area) ops.fail("d2", "must be in the area of d1");
    if (d2.index < d1.index) ops.fail("d2", "must not come before d1");
    const Zone z = zone_of(ops, "d1", ctx, d1, d2);
    return std::make_unique<Rst>(en, z.bits, z.words, "ZRST", pulse);
}

}  // namespace plcemu::instructions
