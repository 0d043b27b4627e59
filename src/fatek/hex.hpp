#pragma once
// The hexadecimal and decimal fields of FATEK frames (docs/profile-fbs.md, "FATEK protocol"):
// numbers are upper-case hex of a fixed width in replies; requests may use either case.

#include <cstddef>
#include <cstdint>
#include <optional>
#include <span>

namespace plcemu::fatek {

/// The value of one hex digit (either case), or -1.
constexpr int hex_digit(std::uint8_t c) noexcept {
    if (c >= '0' && c <= '9') return c - '0';
    if (c >= 'A' && c <= 'F') return c - 'A' + 10;
    if (c >= 'a' && c <= 'f') return c - 'a' + 10;
    return -1;
}

/// The number the hex digits of `s` spell (at most 8), or nothing when one is not a hex digit.
constexpr std::optional<std::uint32_t> parse_hex(std::span<const std::uint8_t> s) noexcept {
    std::uint32_t v = 0;
    for (const std::uint8_t c : s) {
        const int d = hex_digit(c);
        if (d < 0) return std::nullopt;
        v = v << 4 | static_cast<std::uint32_t>(d);
    }
    return v;
}

/// The number the decimal digits of `s` spell, or nothing when one is not a digit.
constexpr std::optional<std::uint32_t> parse_decimal(std::span<const std::uint8_t> s) noexcept {
    std::uint32_t v = 0;
    for (const std::uint8_t c : s) {
        if (c < '0' || c > '9') return std::nullopt;
        v = v * 10 + static_cast<std::uint32_t>(c - '0');
    }
    return v;
}

/// Writes `v` as `digits` upper-case hex digits at `out`; returns the end.
inline std::uint8_t* put_hex(std::uint8_t* out, std::uint32_t v, int digits) noexcept {
    constexpr char kDigits[] = "0123456789ABCDEF";
    for (int i = digits - 1; i >= 0; --i) {
        out[i] = static_cast<std::uint8_t>(kDigits[v & 0xF]);
        v >>= 4;
    }
    return out + digits;
}

}  // namespace plcemu::fatek
