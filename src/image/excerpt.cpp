#include "plcemu/image/excerpt.hpp"

#include <algorithm>
#include <cstdio>
#include <utility>

#include "plcemu/image/utf8.hpp"

namespace plcemu::image {

namespace {

// What a terminal acts on instead of showing: C0 and C1 controls, DEL, the line and paragraph
// separators, and the bidirectional marks, embeddings, overrides and isolates (which reorder the
// rest of the line); and what it shows as nothing, which would make a quoted name look like
// another: Unicode's default-ignorable code points (DerivedCoreProperties.txt,
// Default_Ignorable_Code_Point: soft hyphen, zero-width space and joiners, invisible operators,
// variation selectors, fillers, the byte order mark, tag characters).
bool escaped(char32_t c) {
    if (c < 0x20 || (c >= 0x7F && c <= 0x9F) || c == 0x2028 || c == 0x2029) return true;
    static constexpr std::pair<char32_t, char32_t> kIgnorable[] = {
        {0x00AD, 0x00AD},   {0x034F, 0x034F}, {0x061C, 0x061C},   {0x115F, 0x1160},
        {0x17B4, 0x17B5},   {0x180B, 0x180F}, {0x200B, 0x200F},   {0x202A, 0x202E},
        {0x2060, 0x206F},   {0x3164, 0x3164}, {0xFE00, 0xFE0F},   {0xFEFF, 0xFEFF},
        {0xFFA0, 0xFFA0},   {0xFFF0, 0xFFF8}, {0x1BCA0, 0x1BCA3}, {0x1D173, 0x1D17A},
        {0xE0000, 0xE0FFF},
    };
    for (const auto& [lo, hi] : kIgnorable) {
        if (c >= lo && c <= hi) return true;
    }
    return false;
}

}  // namespace

// Escapes, besides controls, the characters that reorder or separate a terminal line (U+202E,
// U+2066, U+2028, …) and bytes that are not UTF-8 (\xFF), so a quote can neither break, forge nor
// reorder a log line. Counts characters, not bytes, so a cut never splits a UTF-8 sequence.
std::string excerpt(std::string_view s, std::size_t max_chars) {
    std::string out;
    // Enough unless something is escaped: an error message quotes one per refusal.
    out.reserve(std::min(s.size(), max_chars) + 4);
    std::size_t chars = 0;
    char hex[12];
    for (std::size_t i = 0; i < s.size();) {
        if (chars++ == max_chars) return out + "…";
        const Utf8Char u = utf8_char(s.substr(i));
        if (u.length == 0) {  // a byte that is not UTF-8
            std::snprintf(hex, sizeof hex, "\\x%02X", static_cast<unsigned char>(s[i]));
            out += hex;
            ++i;
            continue;
        }
        if (u.code == '\n') {
            out += "\\n";
        } else if (u.code == '\r') {
            out += "\\r";
        } else if (u.code == '\t') {
            out += "\\t";
        } else if (u.code < 0x20 || u.code == 0x7F) {
            std::snprintf(hex, sizeof hex, "\\x%02X", static_cast<unsigned>(u.code));
            out += hex;
        } else if (escaped(u.code)) {
            std::snprintf(hex, sizeof hex, u.code > 0xFFFF ? "\\U%08X" : "\\u%04X",
                          static_cast<unsigned>(u.code));
            out += hex;
        } else {
            out.append(s, i, u.length);
        }
        i += u.length;
    }
    return out;
}

}  // namespace plcemu::image
