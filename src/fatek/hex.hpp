#pragma once
// The hexadecimal and decimal fields of FATEK frames (docs/profile-fbs.md, "FATEK protocol"):
// numbers are upper-case hex of a fixed width in replies; requests may use either case.

#include <array>
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

namespace detail {

// Two upper-case hex digits per byte value: a reply of 64 registers writes 128 pairs.
struct HexPairs {
    std::array<std::array<std::uint8_t, 2>, 256> pair{};
    constexpr HexPairs() {
        constexpr char kDigits[] = "0123456789ABCDEF";
        for (std::size_t b = 0; b < 256; ++b) {
            pair[b] = {static_cast<std::uint8_t>(kDigits[b >> 4]),
                       static_cast<std::uint8_t>(kDigits[b & 0xF])};
        }
    }
};
inline constexpr HexPairs kHexPairs{};

}  // namespace detail

/// Writes `v` as `digits` (2, 4, 6 or 8) upper-case hex digits at `out`; returns the end.
inline std::uint8_t* put_hex(std::uint8_t* out, std::uint32_t v, int digits) noexcept {
    for (int i = digits - 2; i >= 0; i -= 2) {
        const auto& p = detail::kHexPairs.pair[v & 0xFF];
        out[i] = p[0];
        out[i + 1] = p[1];
        v >>= 8;
    }
    return out + digits;
}

}  // namespace plcemu::fatek
