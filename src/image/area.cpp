#include "plcemu/image/area.hpp"

#include <array>
#include <charconv>

namespace plcemu::image {

namespace {

struct Prefix {
    std::string_view text;
    Area area;
};

// Longest prefixes first so that "TMR" wins over "T" and "CTR" over "C".
constexpr std::array<Prefix, 10> kPrefixes{{
    {"TMR", Area::TV},
    {"CTR", Area::CV},
    {"X", Area::X},
    {"Y", Area::Y},
    {"M", Area::M},
    {"S", Area::S},
    {"T", Area::T},
    {"C", Area::C},
    {"R", Area::R},
    {"D", Area::D},
}};

// Counter values: C0-C199 take one word each, C200-C255 two (low word first), so a counter
// number is not its word index in the CV area.
constexpr std::uint32_t kFirst32BitCounter = 200;

std::uint32_t counter_word(std::uint32_t n) {
    return n < kFirst32BitCounter ? n : kFirst32BitCounter + 2 * (n - kFirst32BitCounter);
}

std::uint32_t counter_of_word(std::uint32_t w) {
    return w < kFirst32BitCounter ? w : kFirst32BitCounter + (w - kFirst32BitCounter) / 2;
}

std::uint32_t counter_words(std::uint32_t n) { return n < kFirst32BitCounter ? 1 : 2; }

bool parse_index(std::string_view digits, std::uint32_t& out) {
    if (digits.empty()) return false;
    auto [p, ec] = std::from_chars(digits.data(), digits.data() + digits.size(), out);
    return ec == std::errc{} && p == digits.data() + digits.size();
}

}  // namespace

std::string_view area_name(Area a) {
    switch (a) {
        case Area::X:
            return "X";
        case Area::Y:
            return "Y";
        case Area::M:
            return "M";
        case Area::S:
            return "S";
        case Area::T:
            return "T";
        case Area::C:
            return "C";
        case Area::R:
            return "R";
        case Area::D:
            return "D";
        case Area::TV:
            return "TMR";
        case Area::CV:
            return "CTR";
    }
    return "?";
}

std::string format_range(const Range& r) {
    std::string name(area_name(r.area));
    std::uint32_t first = r.start;
    std::uint32_t last = r.start + (r.count > 0 ? r.count - 1 : 0);
    if (r.area == Area::CV) {
        first = counter_of_word(first);
        last = counter_of_word(last);
    }
    std::string s = name + std::to_string(first);
    if (last != first) s += "-" + name + std::to_string(last);
    return s;
}

std::optional<Device> parse_device(std::string_view text) {
    Device d;
    if (text.size() > 1 && (text[0] == 'W' || text[0] == 'w') &&
        !(text[1] >= '0' && text[1] <= '9')) {
        d.word_of_bits = true;
        text.remove_prefix(1);
    }
    for (const auto& p : kPrefixes) {
        if (text.size() <= p.text.size()) continue;
        bool match = true;
        for (std::size_t i = 0; i < p.text.size(); ++i) {
            char c = text[i];
            if (c >= 'a' && c <= 'z') c = static_cast<char>(c - 'a' + 'A');
            if (c != p.text[i]) match = false;
        }
        if (!match) continue;
        if (!parse_index(text.substr(p.text.size()), d.index)) return std::nullopt;
        d.area = p.area;
        if (d.area == Area::CV) {
            if (d.index > 0xFFFF) return std::nullopt;  // no such counter; keeps the math exact
            d.index = counter_word(d.index);
        }
        if (d.word_of_bits && !is_bit_area(d.area)) return std::nullopt;
        return d;
    }
    return std::nullopt;
}

std::optional<Range> parse_range(std::string_view text) {
    auto dash = text.find('-');
    auto first = parse_device(text.substr(0, dash));
    if (!first || first->word_of_bits) return std::nullopt;
    std::uint32_t last = first->index;
    if (dash != std::string_view::npos) {
        auto second = parse_device(text.substr(dash + 1));
        if (!second || second->word_of_bits || second->area != first->area) return std::nullopt;
        last = second->index;
    }
    if (last < first->index) return std::nullopt;
    // A 32-bit counter at the end of a range brings its high word along.
    const std::uint32_t tail =
        first->area == Area::CV ? counter_words(counter_of_word(last)) - 1 : 0;
    return Range{first->area, first->index, last - first->index + 1 + tail};
}

}  // namespace plcemu::image
