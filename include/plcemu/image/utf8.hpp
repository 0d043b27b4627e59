#pragma once
// UTF-8 as RFC 3629 defines it: what excerpt() escapes and the tag export's JSON replaces is
// every byte that is not part of a well-formed character.

#include <cstddef>
#include <string_view>

namespace plcemu::image {

/// One character of UTF-8 text: its code point and length in bytes, or length 0 when the bytes at
/// the start of the text are not a well-formed UTF-8 sequence (overlong, a surrogate, above
/// U+10FFFF, cut short).
struct Utf8Char {
    char32_t code = 0;       ///< the code point (0 when `length` is 0)
    std::size_t length = 0;  ///< bytes it takes, 1 to 4; 0 = not UTF-8
};

/// Decodes the character at the start of `text` (which must not be empty).
Utf8Char utf8_char(std::string_view text) noexcept;

}  // namespace plcemu::image
