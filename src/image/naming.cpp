#include "plcemu/image/naming.hpp"

#include <cstdio>

namespace plcemu::image {

namespace {

constexpr long long kIntegerLimit = 1LL << 40;

char upper(char c) { return c >= 'a' && c <= 'z' ? static_cast<char>(c - 'a' + 'A') : c; }

bool starts_with_nocase(std::string_view text, std::string_view prefix) {
    if (text.size() < prefix.size()) return false;
    for (std::size_t i = 0; i < prefix.size(); ++i) {
        if (upper(text[i]) != prefix[i]) return false;
    }
    return true;
}

// Digits in `radix`; at most 10 digits, so the value always fits.
bool parse_index(std::string_view digits, unsigned radix, std::uint32_t& out) {
    if (digits.empty() || digits.size() > 10) return false;
    std::uint64_t v = 0;
    for (char c : digits) {
        const unsigned d = static_cast<unsigned>(c - '0');
        if (c < '0' || c > '9' || d >= radix) return false;
        v = v * radix + d;
    }
    if (v > 0xFFFFFFFFu) return false;
    out = static_cast<std::uint32_t>(v);
    return true;
}

}  // namespace

std::uint32_t Naming::counter_word(std::uint32_t n) const {
    return n < first_32bit_counter ? n : first_32bit_counter + 2 * (n - first_32bit_counter);
}

std::uint32_t Naming::counter_of_word(std::uint32_t w) const {
    return w < first_32bit_counter ? w : first_32bit_counter + (w - first_32bit_counter) / 2;
}

std::uint32_t Naming::counter_words(std::uint32_t n) const {
    return n < first_32bit_counter ? 1 : 2;
}

Range Naming::devices_from(const Device& d, std::uint32_t n) const {
    if (n == 0) return {d.area, d.index, 0};
    if (d.word_of_bits) return {d.area, d.index, n * 16};
    if (d.area == Area::CV) {
        const std::uint32_t last = counter_of_word(d.index) + n - 1;
        return {d.area, d.index, counter_word(last) + counter_words(last) - d.index};
    }
    return {d.area, d.index, n};
}

std::uint32_t Naming::devices_in(const Range& r) const {
    if (r.area != Area::CV || r.count == 0) return r.count;
    return counter_of_word(r.end() - 1) - counter_of_word(r.start) + 1;
}

std::optional<Device> Naming::parse_device(std::string_view text) const {
    Device d;
    if (text.size() > 1 && upper(text[0]) == 'W' && !(text[1] >= '0' && text[1] <= '9')) {
        d.word_of_bits = true;
        text.remove_prefix(1);
    }
    for (const auto& p : prefixes) {
        if (text.size() <= p.text.size() || !starts_with_nocase(text, p.text)) continue;
        const unsigned base = radix[static_cast<std::size_t>(p.area)] == 8 ? 8 : 10;
        if (!parse_index(text.substr(p.text.size()), base, d.index)) return std::nullopt;
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

std::optional<Range> Naming::parse_range(std::string_view text) const {
    const auto dash = text.find('-');
    const auto first = parse_device(text.substr(0, dash));
    if (!first || first->word_of_bits) return std::nullopt;
    std::uint32_t last = first->index;
    if (dash != std::string_view::npos) {
        const auto second = parse_device(text.substr(dash + 1));
        if (!second || second->word_of_bits || second->area != first->area) return std::nullopt;
        last = second->index;
    }
    if (last < first->index) return std::nullopt;
    // A 32-bit counter at the end of a range brings its high word along.
    const std::uint32_t tail =
        first->area == Area::CV ? counter_words(counter_of_word(last)) - 1 : 0;
    return Range{first->area, first->index, last - first->index + 1 + tail};
}

std::string Naming::format_device(Area a, std::uint32_t index) const {
    std::string s(area_name(a).empty() ? image::area_name(a) : area_name(a));
    if (a == Area::CV) index = counter_of_word(index);
    if (radix[static_cast<std::size_t>(a)] == 8) {
        char buf[16];
        std::snprintf(buf, sizeof buf, "%o", index);
        return s + buf;
    }
    return s + std::to_string(index);
}

std::string Naming::last_of(Area a, std::uint32_t size) const {
    std::string s = "the last ";
    s += area_name(a);
    s += ", ";
    s += format_device(a, size - 1);
    return s;
}

std::string Naming::format_range(const Range& r) const {
    const std::uint32_t last = r.start + (r.count > 0 ? r.count - 1 : 0);
    std::string s = format_device(r.area, r.start);
    const bool one =
        r.area == Area::CV ? counter_of_word(last) == counter_of_word(r.start) : last == r.start;
    if (!one) {
        // Two appends: GCC 12 warns (-Wrestrict, a false positive, GCC bug 105329) on
        // "-" + std::string at -O2 and up, which a -DPLCEMU_WERROR=ON Release build stops on.
        s += '-';
        s += format_device(r.area, last);
    }
    return s;
}

std::string Naming::why_not(std::string_view text) const {
    std::string areas;
    bool hit = false;
    for (const auto& p : prefixes) {
        if (radix[static_cast<std::size_t>(p.area)] != 8) continue;
        areas += (areas.empty() ? "" : " and ") + std::string(p.text);
        hit = hit || (starts_with_nocase(text, p.text) &&
                      text.find_first_of("89", p.text.size()) != std::string_view::npos);
    }
    return hit ? areas + " are numbered in octal: 7 is followed by 10" : "";
}

bool Naming::parse_integer(std::string_view s, long long& out, bool* too_large) const {
    if (s.empty()) return false;
    bool neg = false;
    if (s[0] == '-' || s[0] == '+') {
        neg = s[0] == '-';
        s.remove_prefix(1);
    }
    unsigned base = 10;
    if (s.size() > 2 && s[0] == '0' && (s[1] == 'x' || s[1] == 'X')) {
        base = 16;
        s.remove_prefix(2);
    } else if (s.size() > 1 && (s.back() == 'h' || s.back() == 'H')) {
        base = 16;  // the manual's 0A556h
        s.remove_suffix(1);
    } else if (s.size() > 1 && upper(s[0]) == 'K') {
        s.remove_prefix(1);                                // constant prefix: K100
        if (!s.empty() && (s[0] == '-' || s[0] == '+')) {  // K-5
            if (neg) return false;
            neg = s[0] == '-';
            s.remove_prefix(1);
        }
    } else if (hex_prefix_h && s.size() > 1 && upper(s[0]) == 'H') {
        base = 16;  // FX-style H0011
        s.remove_prefix(1);
    }
    if (s.empty()) return false;
    long long v = 0;
    bool over = false;
    for (char c : s) {
        unsigned d = 16;
        if (c >= '0' && c <= '9') d = static_cast<unsigned>(c - '0');
        if (c >= 'a' && c <= 'f') d = static_cast<unsigned>(c - 'a' + 10);
        if (c >= 'A' && c <= 'F') d = static_cast<unsigned>(c - 'A' + 10);
        if (d >= base) return false;
        // Past the limit the digits are still read, to tell a number too large from no number.
        if (over) continue;
        v = v * base + d;
        over = v > kIntegerLimit;
    }
    if (over) {
        if (too_large != nullptr) *too_large = true;
        return false;
    }
    out = neg ? -v : v;
    return true;
}

}  // namespace plcemu::image
