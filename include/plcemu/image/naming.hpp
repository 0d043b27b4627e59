#pragma once
// How a PLC family writes its devices and constants: which letters name which area, whether an
// area is numbered in decimal or octal, and how values of 32-bit counters are laid out. A
// profile owns one Naming; the image, the config loader and the instructions only read it.

#include <array>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "plcemu/image/area.hpp"

namespace plcemu::image {

/// The spelling of a family's devices and constants.
struct Naming {
    /// One device prefix ("TMR" for timer values, "X" for inputs).
    struct Prefix {
        std::string_view text;  ///< upper case; parsing ignores case
        Area area;              ///< the area it names
    };
    /// Prefixes the parser accepts (longest first, so "TMR" wins over "T").
    std::vector<Prefix> prefixes;
    /// The prefix ranges and errors are printed with, per area (empty: the area does not exist).
    std::array<std::string_view, kAreaCount> names{};
    /// 8 for areas numbered in octal (X10 is the ninth input), else 10.
    std::array<std::uint8_t, kAreaCount> radix{};
    /// The first counter whose value takes two words (low word first); counters below take one.
    std::uint32_t first_32bit_counter = 0xFFFFFFFF;
    /// True when constants may be written as the FX family writes them: H1F (hex), K31.
    bool hex_prefix_h = false;

    /// Word index in the counter-value area of counter `n`.
    std::uint32_t counter_word(std::uint32_t n) const;
    /// The counter whose value holds word `w`.
    std::uint32_t counter_of_word(std::uint32_t w) const;
    /// Words of counter `n`'s value: 1 or 2.
    std::uint32_t counter_words(std::uint32_t n) const;
    /// The `n` devices from `d` as a range of its area: WM800 and 2 are the 32 bits M800-M831,
    /// CTR200 and 2 the four words of two 32-bit counters. As the devices API and the
    /// communication faults count devices.
    Range devices_from(const Device& d, std::uint32_t n) const;
    /// How many devices `r` holds: its entries, or the counters whose words it holds.
    std::uint32_t devices_in(const Range& r) const;

    /// Parses "R100", "d0", "WM800" (16 bits as a word), "X17" (octal where the area is).
    /// Returns nothing for text that is not a device of this family. Index limits are the
    /// layout's (Layout::contains), except that an octal number must be written in octal.
    std::optional<Device> parse_device(std::string_view text) const;
    /// Parses "D100-D199" or one device as a range (no word of bits); a counter-value range
    /// ending at a 32-bit counter includes its high word.
    std::optional<Range> parse_range(std::string_view text) const;
    /// The range in the family's notation: "D100-D199", "Y10-Y17" (octal), "TMR0-TMR255".
    std::string format_range(const Range& r) const;
    /// One device's name, e.g. "Y17".
    std::string format_device(Area a, std::uint32_t index) const;
    /// "the last R, R8071": the end a span of an area of `size` devices ran past, as the
    /// operands and the devices endpoint refuse it.
    std::string last_of(Area a, std::uint32_t size) const;
    /// The name of an area ("" when the family has none).
    std::string_view area_name(Area a) const { return names[static_cast<std::size_t>(a)]; }
    /// Why `text`, refused as a device, may have been meant as one: "X and Y are numbered in
    /// octal: 7 is followed by 10" when it names an octal area with a digit 8 or 9 (X8 on a VB),
    /// else "". Errors about a device add it.
    std::string why_not(std::string_view text) const;

    /// The one integer grammar of configs, presets and operands: decimal with an optional sign,
    /// 0x1F, the manual's 1Fh / 0A556h, K31 and, for families that write them, H1F. Values
    /// beyond ±2^40 are refused.
    /// `too_large`, when given, is set when `text` is a well-formed integer beyond ±2^40.
    bool parse_integer(std::string_view text, long long& out, bool* too_large = nullptr) const;
};

}  // namespace plcemu::image
