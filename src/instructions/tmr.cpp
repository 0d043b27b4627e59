#include "tmr.hpp"

#include <algorithm>

#include "operands.hpp"

namespace plcemu::instructions {

namespace {

using image::Area;

class Tmr final : public engine::Instruction {
public:
    struct Bound {
        BitSource en;
        std::uint32_t timer = 0;  // timer number: contact T, value TV
        TimerGroup group;         // its time base
        WordSource k;             // set value (signed)
    };

    explicit Tmr(Bound b)
        : b_(b) {}

    void execute(engine::ScanContext& ctx) noexcept override {
        image::Image& img = ctx.image;
        if (!b_.en.read(img)) {
            if (b_.group.retentive) return;  // value, contact and the time below a count stay
            rest_ = engine::Duration::zero();
            write(img, 0, false);
            return;
        }
        long long v = static_cast<std::int16_t>(img.word(Area::TV, b_.timer));
        // A value someone else wrote (RST, a master) starts from a whole count.
        if (v != last_) rest_ = engine::Duration::zero();
        const long long k = static_cast<std::int16_t>(b_.k.read(img));
        rest_ += ctx.dt;
        const long long ticks = rest_ / b_.group.base;
        rest_ %= b_.group.base;
        if (v < k) v = std::min(v + ticks, k);
        write(img, v, v >= k);
    }

    std::string_view mnemonic() const noexcept override { return "TMR"; }

private:
    void write(image::Image& img, long long v, bool contact) noexcept {
        last_ = v;
        img.set_word(Area::TV, b_.timer, static_cast<std::uint16_t>(v));
        img.set_bit(Area::T, b_.timer, contact);
    }

    Bound b_;
    engine::Duration rest_{0};  // time below one count, kept between scans
    long long last_ = 0;        // the value this timer wrote last
};

// The profile's group of timer `n`, if it has one with a usable base.
const TimerGroup* group_of(const BindContext& ctx, std::uint32_t n) {
    const auto* ts = dynamic_cast<const TimerServices*>(&ctx.services);
    if (!ts) return nullptr;
    for (const auto& g : ts->timers) {
        if (n >= g.first && n - g.first < g.count && g.base > engine::Duration::zero()) return &g;
    }
    return nullptr;
}

}  // namespace

std::unique_ptr<engine::Instruction> make_tmr(const Entry& ic, const BindContext& ctx) {
    Operands ops(ic, ctx);
    Tmr::Bound b;
    b.en = ops.bit_source("en", true);
    b.timer = ops.device("t", 1, {Area::T}).index;
    const TimerGroup* group = group_of(ctx, b.timer);
    if (!group || !ctx.layout.contains({Area::TV, b.timer, 1})) {
        ops.fail("t", "timer " + ctx.naming.format_device(Area::T, b.timer) +
                          " has no time base in this PLC");
    }
    b.group = *group;
    ops.note("t", {Area::TV, b.timer, 1}, "value");
    if (ops.numeric("k")) {
        b.k = {true, static_cast<std::uint16_t>(ops.integer("k", 0, 32767)), {}};
    } else {
        b.k = ops.word_source("k");
    }
    ops.finish();
    return std::make_unique<Tmr>(b);
}

}  // namespace plcemu::instructions
