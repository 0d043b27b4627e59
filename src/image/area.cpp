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

bool parse_index(std::string_view digits, std::uint32_t& out) {
    if (digits.empty()) return false;
    auto [p, ec] = std::from_chars(digits.data(), digits.data() + digits.size(), out);
    return ec == std::errc{} && p == digits.data() + digits.size();
}

}  // namespace

std::string_view area_name(Area a) {
    switch (a) {
        case Area::X: return "X";
        case Area::Y: return "Y";
        case Area::M: return "M";
        case Area::S: return "S";
        case Area::T: return "T";
        case Area::C: return "C";
        case Area::R: return "R";
        case Area::D: return "D";
        case Area::TV: return "TMR";
        case Area::CV: return "CTR";
    }
    return "?";
}

std::string format_range(const Range& r) {
    std::string name(area_name(r.area));
    std::string s = name + std::to_string(r.start);
    if (r.count > 1) s += "-" + name + std::to_string(r.start + r.count - 1);
    return s;
}

std::optional<Device> parse_device(std::string_view text) {
    Device d;
    if (text.size() > 1 && (text[0] == 'W' || text[0] == 'w') && !(text[1] >= '0' && text[1] <= '9')) {
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
    return Range{first->area, first->index, last - first->index + 1};
}

}  // namespace plcemu::image
