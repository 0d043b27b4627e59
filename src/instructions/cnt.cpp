#include "cnt.hpp"

#include <optional>

#include "edge.hpp"
#include "operands.hpp"

namespace plcemu::instructions {

namespace {

using image::Area;

class Cnt final : public engine::Instruction {
public:
    struct Bound {
        BitSource en;
        std::uint32_t counter = 0;               // counter number
        std::uint32_t value_word = 0;            // its first word in the counter-value area
        bool wide = false;                       // 32-bit
        bool k_constant = true;                  // K as a constant
        long long k = 0;                         // the constant
        image::Device k_device;                  // K's (first) word otherwise
        std::optional<image::Device> direction;  // relay: ON = count down
    };

    explicit Cnt(Bound b)
        : b_(b) {}

    void execute(engine::ScanContext& ctx) noexcept override {
        image::Image& img = ctx.image;
        const bool edge = edge_(b_.en.read(img), ctx.first_scan);
        long long k = b_.k;
        if (!b_.k_constant) {
            const std::uint32_t lo = img.read_word(b_.k_device);
            if (b_.wide) {
                image::Device hi = b_.k_device;
                hi.index += 1;
                k = static_cast<std::int32_t>(lo | static_cast<std::uint32_t>(img.read_word(hi))
                                                       << 16);
            } else {
                k = static_cast<std::int16_t>(lo);
            }
        }
        if (!b_.wide) {
            // Signed, as a timer's value: one a master wrote negative counts up towards K.
            long long v = static_cast<std::int16_t>(img.word(Area::CV, b_.value_word));
            if (edge && v < k) ++v;
            img.set_word(Area::CV, b_.value_word, static_cast<std::uint16_t>(v));
            img.set_bit(Area::C, b_.counter, v >= k);
            return;
        }
        const std::uint32_t raw = img.word(Area::CV, b_.value_word) |
                                  static_cast<std::uint32_t>(img.word(Area::CV, b_.value_word + 1))
                                      << 16;
        auto v = static_cast<std::int32_t>(raw);
        const bool down = b_.direction && img.read_bit(*b_.direction);
        if (edge) {
            // The 32-bit counters wrap around at the ends of their range, as the FX family's do.
            v = static_cast<std::int32_t>(static_cast<std::uint32_t>(v) +
                                          (down ? 0xFFFFFFFFu : 1u));
        }
        const auto u = static_cast<std::uint32_t>(v);
        img.set_word(Area::CV, b_.value_word, static_cast<std::uint16_t>(u & 0xFFFF));
        img.set_word(Area::CV, b_.value_word + 1, static_cast<std::uint16_t>(u >> 16));
        img.set_bit(Area::C, b_.counter, v >= k);
    }

    std::string_view mnemonic() const noexcept override { return "CNT"; }

private:
    Bound b_;
    RisingEdge edge_;
};

}  // namespace

std::unique_ptr<engine::Instruction> make_cnt(const Entry& ic, const BindContext& ctx) {
    Operands ops(ic, ctx);
    Cnt::Bound b;
    b.en = ops.bit_source("en", true);
    const image::Device c = ops.device("c", 1, {Area::C});
    b.counter = c.index;
    b.wide = ctx.naming.counter_words(c.index) == 2;
    b.value_word = ctx.naming.counter_word(c.index);
    if (!ctx.layout.contains({Area::CV, b.value_word, b.wide ? 2u : 1u})) {
        ops.fail("c", "counter " + ctx.naming.format_device(Area::C, c.index) +
                          " has no current value in this PLC");
    }
    ops.note("c", {Area::CV, b.value_word, b.wide ? 2u : 1u}, "value");
    if (ops.numeric("k")) {
        b.k = b.wide ? ops.integer("k", -2147483648LL, 2147483647LL) : ops.integer("k", 0, 32767);
    } else {
        b.k_constant = false;
        b.k_device = ops.word_device("k", b.wide ? 2 : 1, {Area::D, Area::R});
    }
    if (b.wide) {
        if (const auto* cs = dynamic_cast<const CounterServices*>(&ctx.services)) {
            const std::uint32_t nth = c.index - ctx.naming.first_32bit_counter;
            const image::Device rel{cs->direction.area, cs->direction.first_relay + nth, false};
            if (nth < cs->direction.counters && ctx.layout.contains({rel.area, rel.index, 1})) {
                b.direction = rel;
            }
        }
    }
    ops.finish();
    return std::make_unique<Cnt>(b);
}

}  // namespace plcemu::instructions
