#include "plcemu/image/utf8.hpp"

namespace plcemu::image {

Utf8Char utf8_char(std::string_view s) noexcept {
    const auto b = [&](std::size_t k) -> unsigned char {
        return k < s.size() ? static_cast<unsigned char>(s[k]) : 0;
    };
    const unsigned char c = b(0);
    if (c < 0x80) return {c, 1};
    // Unicode's table 3-7 (RFC 3629 §4): the second byte's range depends on the lead (no overlongs,
    // no surrogates, nothing above U+10FFFF); later bytes are 80–BF.
    std::size_t length = 0;
    unsigned char low = 0x80;
    unsigned char high = 0xBF;
    if (c >= 0xC2 && c <= 0xDF) {
        length = 2;
    } else if (c >= 0xE0 && c <= 0xEF) {
        length = 3;
        if (c == 0xE0) low = 0xA0;
        if (c == 0xED) high = 0x9F;
    } else if (c >= 0xF0 && c <= 0xF4) {
        length = 4;
        if (c == 0xF0) low = 0x90;
        if (c == 0xF4) high = 0x8F;
    } else {
        return {};
    }
    if (b(1) < low || b(1) > high) return {};
    auto code = static_cast<char32_t>(c & (0x7F >> length));
    for (std::size_t k = 1; k < length; ++k) {
        if (k > 1 && (b(k) & 0xC0) != 0x80) return {};
        code = (code << 6) | static_cast<char32_t>(b(k) & 0x3F);
    }
    return {code, length};
}

}  // namespace plcemu::image
