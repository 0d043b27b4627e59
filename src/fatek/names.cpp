#include "names.hpp"

#include <algorithm>
#include <array>
#include <string>
#include <string_view>

#include "hex.hpp"
#include "plcemu/fatek/device_name.hpp"

namespace plcemu::fatek {

namespace {

using image::Area;

struct Prefix {
    std::string_view letters;
    Form form;
    Area area;
    std::uint8_t digits;
};

// Every prefix of the protocol, the registers masters read most first (a parse tries them in
// order); the area is where the number counts (RC: counters, whose 16-bit values are one word
// each and the 32-bit ones two).
constexpr std::array<Prefix, 28> kPrefixes{{
    {"R", Form::Register, Area::R, 5},     {"D", Form::Register, Area::D, 5},
    {"DR", Form::Pair, Area::R, 5},        {"DD", Form::Pair, Area::D, 5},
    {"X", Form::Discrete, Area::X, 4},     {"Y", Form::Discrete, Area::Y, 4},
    {"M", Form::Discrete, Area::M, 4},     {"S", Form::Discrete, Area::S, 4},
    {"T", Form::Discrete, Area::T, 4},     {"C", Form::Discrete, Area::C, 4},
    {"RT", Form::Register, Area::TV, 4},   {"RC", Form::Register, Area::CV, 4},
    {"DRC", Form::Counter32, Area::CV, 4}, {"DRT", Form::Absent, Area::TV, 4},
    {"WX", Form::Packed16, Area::X, 4},    {"WY", Form::Packed16, Area::Y, 4},
    {"WM", Form::Packed16, Area::M, 4},    {"WS", Form::Packed16, Area::S, 4},
    {"WT", Form::Packed16, Area::T, 4},    {"WC", Form::Packed16, Area::C, 4},
    {"DWX", Form::Packed32, Area::X, 4},   {"DWY", Form::Packed32, Area::Y, 4},
    {"DWM", Form::Packed32, Area::M, 4},   {"DWS", Form::Packed32, Area::S, 4},
    {"DWT", Form::Packed32, Area::T, 4},   {"DWC", Form::Packed32, Area::C, 4},
    {"F", Form::Absent, Area::R, 5},       {"DF", Form::Absent, Area::R, 5},
}};

constexpr bool upper(std::uint8_t c) { return c >= 'A' && c <= 'Z'; }

// The counters' split: C0.. one word each, then the 32-bit ones two words each, so that the
// counter-value area holds (16-bit counters + 2 x 32-bit counters) words.
struct Counters {
    std::uint32_t narrow;  // 16-bit counters, C0 up
    std::uint32_t all;     // counters
};

Counters counters(const image::Layout& layout) {
    const std::uint32_t all = layout.size_of(Area::C);
    const std::uint32_t words = layout.size_of(Area::CV);
    const std::uint32_t wide = words > all ? words - all : 0;
    return {wide > all ? 0 : all - wide, all};
}

}  // namespace

NameParse parse_name(std::span<const std::uint8_t> text) noexcept {
    std::size_t n = 0;
    while (n < text.size() && upper(text[n])) ++n;
    if (n == 0) return {Error::Format, {}};
    for (const Prefix& p : kPrefixes) {
        if (p.letters.size() != n ||
            !std::equal(p.letters.begin(), p.letters.end(), text.begin())) {
            continue;
        }
        if (text.size() - n < p.digits) return {Error::Format, {}};
        const auto number = parse_decimal(text.subspan(n, p.digits));
        if (!number) return {Error::Format, {}};
        return {Error::None, {p.form, p.area, *number, static_cast<std::uint8_t>(n + p.digits)}};
    }
    return {Error::Address, {}};
}

Error resolve(const Name& name,
              std::uint32_t items,
              const image::Layout& layout,
              Run& run) noexcept {
    run = {name.form, name.area, name.number, 1, items};
    switch (name.form) {
        case Form::Absent:
            return Error::Address;
        case Form::Discrete:
            break;
        case Form::Register:
            if (name.area == Area::CV && name.number + items > counters(layout).narrow) {
                return Error::Address;
            }
            break;
        case Form::Pair:
            run.step = 2;
            break;
        case Form::Counter32: {
            const Counters c = counters(layout);
            if (name.number < c.narrow || name.number + items > c.all) return Error::Address;
            run.start = c.narrow + 2 * (name.number - c.narrow);
            run.step = 2;
            break;
        }
        case Form::Packed16:
        case Form::Packed32:
            // The W forms start at a multiple of 8 (docs/profile-fbs.md, "FATEK protocol").
            if (name.number % 8 != 0) return Error::Address;
            run.step = name.form == Form::Packed16 ? 16 : 32;
            break;
    }
    const image::Range devices{run.area, run.start, run.step * items};
    return layout.contains(devices) ? Error::None : Error::Address;
}

std::string device_name(const image::Layout& layout,
                        Area area,
                        std::uint32_t index,
                        bool word_of_bits) {
    Form form = image::is_bit_area(area) ? (word_of_bits ? Form::Packed16 : Form::Discrete)
                                         : Form::Register;
    std::uint32_t number = index;
    if (form == Form::Packed16 && index % 8 != 0) return {};  // N1: W forms at multiples of 8
    if (area == Area::CV) {
        // N3: past the 16-bit counters each 32-bit one takes two words and is named at its low.
        const Counters c = counters(layout);
        if (index >= c.narrow) {
            if ((index - c.narrow) % 2 != 0) return {};
            form = Form::Counter32;
            number = c.narrow + (index - c.narrow) / 2;
        }
    }
    for (const Prefix& p : kPrefixes) {
        if (p.form != form || p.area != area) continue;
        if (number >= (p.digits == 4 ? 10000u : 100000u)) return {};
        const std::string digits = std::to_string(number);
        std::string out(p.letters);
        out.append(p.digits - digits.size(), '0');  // zero-padded to the prefix's width
        out += digits;
        return out;
    }
    return {};
}

}  // namespace plcemu::fatek
