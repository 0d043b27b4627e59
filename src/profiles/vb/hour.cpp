#include "profiles/vb/hour.hpp"

#include <chrono>
#include <cstdint>
#include <limits>

#include "instructions/operands.hpp"

namespace plcemu::profiles::vb {

namespace {

using image::Area;
using instructions::BitSource;
using instructions::Operands;

constexpr long long kSecondsPerHour = 3600;

class Hour final : public engine::Instruction {
public:
    struct Bound {
        BitSource en;
        bool wide = false;       // DHOUR: 32-bit hours and preset
        bool s_constant = true;  // S as a constant
        long long s = 0;         // the constant
        image::Device s_device;  // S's (first) word otherwise
        std::uint32_t d1 = 0;    // hours (one or two words), then the seconds
        image::Device d2;        // alarm output
    };

    explicit Hour(Bound b)
        : b_(b) {}

    void execute(engine::ScanContext& ctx) noexcept override {
        image::Image& img = ctx.image;
        // EN OFF: the count and the alarm keep their values (VB manual FNC169).
        if (!b_.en.read(img)) return;
        const std::uint32_t sec_word = b_.d1 + (b_.wide ? 2 : 1);
        // Written seconds of 3600 or more carry into the hours; written hours count as they are.
        long long total =
            read(img, {Area::D, b_.d1, false}) * kSecondsPerHour + img.word(Area::D, sec_word);
        rest_ += ctx.dt;
        total += rest_ / std::chrono::seconds(1);
        rest_ %= std::chrono::seconds(1);
        const long long max_hours = b_.wide ? std::numeric_limits<std::int32_t>::max()
                                            : std::numeric_limits<std::int16_t>::max();
        const long long max_total = max_hours * kSecondsPerHour + kSecondsPerHour - 1;
        if (total >= max_total) {
            // The count stops at the register's maximum.
            total = max_total;
            rest_ = engine::Duration::zero();
        }
        // Floor division: hours written negative count up towards zero.
        long long hours = total / kSecondsPerHour;
        if (total % kSecondsPerHour < 0) --hours;
        const long long seconds = total - hours * kSecondsPerHour;
        write(img, b_.d1, hours);
        img.set_word(Area::D, sec_word, static_cast<std::uint16_t>(seconds));
        const long long preset = b_.s_constant ? b_.s : read(img, b_.s_device);
        img.write_bit(b_.d2, hours >= preset);
    }

    std::string_view mnemonic() const noexcept override { return b_.wide ? "DHOUR" : "HOUR"; }

private:
    // The signed 16- or 32-bit value from `first` on (low word first).
    long long read(const image::Image& img, image::Device first) const noexcept {
        const std::uint16_t lo = img.read_word(first);
        if (!b_.wide) return static_cast<std::int16_t>(lo);
        ++first.index;
        return static_cast<std::int32_t>(lo | static_cast<std::uint32_t>(img.read_word(first))
                                                  << 16);
    }
    void write(image::Image& img, std::uint32_t index, long long v) const noexcept {
        const auto u = static_cast<std::uint32_t>(v);
        img.set_word(Area::D, index, static_cast<std::uint16_t>(u & 0xFFFF));
        if (b_.wide) img.set_word(Area::D, index + 1, static_cast<std::uint16_t>(u >> 16));
    }

    Bound b_;
    engine::Duration rest_{0};  // below one second; lost at a restart (VB manual FNC169)
};

std::unique_ptr<engine::Instruction> make(const instructions::Entry& ic,
                                          const instructions::BindContext& ctx,
                                          bool wide) {
    Operands ops(ic, ctx);
    Hour::Bound b;
    b.wide = wide;
    b.en = ops.bit_source("en", true);
    if (ops.constant("s")) {
        b.s = ops.integer("s", 0,
                          wide ? std::numeric_limits<std::int32_t>::max()
                               : std::numeric_limits<std::int16_t>::max());
    } else {
        b.s_constant = false;
        b.s_device = wide ? ops.word_device("s", 2, {Area::D}) : ops.word_source("s").device;
    }
    const std::uint32_t span = wide ? 3 : 2;
    b.d1 = ops.output_words("d1", span, {Area::D}).index;
    b.d2 = ops.bit_output("d2");
    ops.finish();
    return std::make_unique<Hour>(b);
}

}  // namespace

std::unique_ptr<engine::Instruction> make_hour(const instructions::Entry& ic,
                                               const instructions::BindContext& ctx) {
    return make(ic, ctx, false);
}

std::unique_ptr<engine::Instruction> make_dhour(const instructions::Entry& ic,
                                                const instructions::BindContext& ctx) {
    return make(ic, ctx, true);
}

}  // namespace plcemu::profiles::vb
