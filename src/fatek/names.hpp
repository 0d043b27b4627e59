#pragma once
// FATEK device names (FBs manual, Appendix 2 FATEK Communication Protocol, device names;
// docs/profile-fbs.md, "FATEK protocol"): a prefix of upper-case letters and a zero-padded
// decimal number of a fixed width (4 digits for discretes, W forms, RT and RC; 5 for R, D, F and
// their 32-bit forms). Parsing reads the syntax (error 4); resolving finds the devices a run of
// items starting at a name covers in the PLC's layout (error A).

#include <cstdint>
#include <span>

#include "error.hpp"
#include "plcemu/image/layout.hpp"

namespace plcemu::fatek {

/// What a name names.
enum class Form : std::uint8_t {
    Discrete,   ///< X Y M S T C: one bit
    Register,   ///< R D RT RC: one 16-bit word
    Pair,       ///< DR DD: a 32-bit value in two registers, low word first
    Counter32,  ///< DRC: a 32-bit counter's value
    Packed16,   ///< WX WY WM WS WT WC: 16 discretes as a word, bit 0 the named one
    Packed32,   ///< DWX ... DWC: 32 discretes as a 32-bit value
    Absent,     ///< F DF DRT: a name the protocol has and the PLC does not
};

/// The width of an item's value in a frame: 1 character, 4 or 8 hex digits.
enum class Width : std::uint8_t { Bit, Word, Dword };

/// A parsed name.
struct Name {
    Form form = Form::Discrete;
    image::Area area = image::Area::X;  ///< the area its number counts in
    std::uint32_t number = 0;           ///< the decimal number
    std::uint8_t length = 0;            ///< characters it took
};

/// A name, or the error reading it gave.
struct NameParse {
    Error error = Error::None;
    Name name;
};

/// Reads the name at the start of `text`: Format for a missing prefix or a wrong digit run,
/// Address for a prefix the protocol does not have.
NameParse parse_name(std::span<const std::uint8_t> text) noexcept;

/// The width of a form's values.
constexpr Width width_of(Form f) noexcept {
    switch (f) {
        case Form::Discrete:
            return Width::Bit;
        case Form::Pair:
        case Form::Counter32:
        case Form::Packed32:
            return Width::Dword;
        default:
            return Width::Word;
    }
}

/// Characters a value of `w` takes in a frame.
constexpr std::uint8_t chars_of(Width w) noexcept {
    return w == Width::Bit ? 1 : w == Width::Word ? 4 : 8;
}

/// Items consecutive to a start name, where they are in the image.
struct Run {
    Form form = Form::Discrete;
    image::Area area = image::Area::X;  ///< the area the values live in
    std::uint32_t start = 0;            ///< index of item 0's first device
    std::uint32_t step = 1;             ///< devices per item (16 for a W form, 2 for a pair)
    std::uint32_t items = 0;            ///< items in the run
};

/// The run of `items` items starting at `name` in `layout`, or Address when one of them does
/// not exist (past the area, in a hole, a W form not at a multiple of 8, RC on a 32-bit counter,
/// DRC on a 16-bit one, an absent area).
Error resolve(const Name& name,
              std::uint32_t items,
              const image::Layout& layout,
              Run& run) noexcept;

}  // namespace plcemu::fatek
