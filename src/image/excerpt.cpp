#include "plcemu/image/excerpt.hpp"

#include <algorithm>
#include <cstdio>

namespace plcemu::image {

// Counts characters, not bytes, so a cut never splits a UTF-8 sequence; stray bytes are escaped.
std::string excerpt(std::string_view s, std::size_t max_chars) {
    static constexpr char kHex[] = "0123456789ABCDEF";
    std::string out;
    // Enough unless something is escaped: an error message quotes one per refusal.
    out.reserve(std::min(s.size(), max_chars) + 4);
    std::size_t chars = 0;
    std::size_t pending = 0;  // continuation bytes the last lead byte announced
    char hex[8];
    for (std::size_t i = 0; i < s.size(); ++i) {
        const auto c = static_cast<unsigned char>(s[i]);
        const auto next = [&](std::size_t k) {
            return i + k < s.size() ? static_cast<unsigned char>(s[i + k]) : 0;
        };
        if ((c & 0xC0) == 0x80 && pending > 0) {
            --pending;
            out += s[i];
            continue;
        }
        pending = 0;
        if (chars++ == max_chars) return out + "…";
        if (c == '\n') {
            out += "\\n";
        } else if (c == '\r') {
            out += "\\r";
        } else if (c == '\t') {
            out += "\\t";
        } else if (c < 0x20 || c == 0x7F || (c & 0xC0) == 0x80 || c >= 0xF8) {
            out += "\\x";
            out += kHex[c >> 4];
            out += kHex[c & 0xF];
        } else if (c == 0xC2 && next(1) >= 0x80 && next(1) <= 0x9F) {  // C1 controls (NEL…)
            std::snprintf(hex, sizeof hex, "\\u%04X", next(1));
            out += hex;
            ++i;
        } else if (c == 0xE2 && next(1) == 0x80 && (next(2) == 0xA8 || next(2) == 0xA9)) {
            out += next(2) == 0xA8 ? "\\u2028" : "\\u2029";  // line and paragraph separators
            i += 2;
        } else {
            pending = c >= 0xF0 ? 3 : c >= 0xE0 ? 2 : c >= 0xC0 ? 1 : 0;
            out += s[i];
        }
    }
    return out;
}

}  // namespace plcemu::image
