#pragma once
// Checked access to an instruction's operands while it binds: every error names the operand's
// file, line and column.

#include <cstdint>
#include <initializer_list>
#include <optional>
#include <set>
#include <string>

#include "plcemu/instructions/instructions.hpp"
#include "plcemu/image/image.hpp"
#include "plcemu/image/layout.hpp"

namespace plcemu::instructions {

/// A bit input: a device or a constant (an enable such as `en: 1`), or the result of the rung
/// the instruction stands on (a listing's function instructions, BindContext::rung).
struct BitSource {
    bool constant = true;        ///< true: `value` is the bit
    bool value = true;           ///< the constant
    image::Device device;        ///< the device otherwise
    const bool* rung = nullptr;  ///< when set, the bit is the rung's result there

    /// The current value.
    bool read(const image::Image& img) const {
        if (rung != nullptr) return *rung;
        return constant ? value : img.read_bit(device);
    }
};

/// A word input: a device (R100, WM800) or a constant (K100, 100).
struct WordSource {
    bool constant = false;    ///< true: `value` is the word
    std::uint16_t value = 0;  ///< the constant
    image::Device device;     ///< the device otherwise

    /// The current value.
    std::uint16_t read(const image::Image& img) const {
        return constant ? value : img.read_word(device);
    }
};

/// The operands of one instruction entry.
class Operands {
public:
    Operands(const Entry& entry, const BindContext& ctx);

    /// True when the operand is present.
    bool has(const char* key) const;
    /// The operand's value when it is present and a constant (K10, 0x1F), not a device.
    std::optional<long long> constant(const char* key) const;
    /// True when the operand is present and written as a number, whether or not any integer
    /// holds it (99999999999999999999): where a constant or a device goes, the constant's
    /// refusal ("out of range") is the one that fits.
    bool numeric(const char* key) const;
    /// A required operand's text as written (a keyword such as CMPOUT's `op`).
    const std::string& text(const char* key) { return require(key).text; }
    /// A bit input; absent gives `fallback`.
    BitSource bit_source(const char* key, bool fallback);
    /// A bit output device (Y, M, S), not on an output the profile reserves.
    image::Device bit_output(const char* key);
    /// An optional bit output (ERR, ALM): bit_output() when present, else none.
    std::optional<image::Device> optional_bit_output(const char* key);
    /// A word input.
    WordSource word_source(const char* key);
    /// A word output: a register or WMn-style bits (WM, WY, WS), not on an output the profile
    /// reserves.
    image::Device word_output(const char* key);
    /// A word device the instruction writes, `span` words from it on, in one of `areas`; the
    /// words may not be ones the profile reserves (file registers, a module's outputs).
    image::Device output_words(const char* key,
                               std::uint32_t span,
                               std::initializer_list<image::Area> areas);
    /// A word device whose `span` consecutive words (or bits, for WMn: 16·span) must exist,
    /// in one of `areas`.
    image::Device word_device(const char* key,
                              std::uint32_t span,
                              std::initializer_list<image::Area> areas);
    /// A device in one of `areas` with `span` consecutive elements.
    image::Device device(const char* key,
                         std::uint32_t span,
                         std::initializer_list<image::Area> areas);
    /// An integer constant in lo..hi.
    long long integer(const char* key, long long lo, long long hi);
    /// A yes/no option (`p: true`) as YAML writes booleans; absent gives `fallback`.
    bool flag(const char* key, bool fallback);
    /// Fails on operands nobody asked for (typos).
    void finish() const;
    /// Throws a BindError at the operand (or at the mnemonic when absent).
    [[noreturn]] void fail(const char* key, const std::string& message) const;
    /// Fails at `key` when `written` lands on an output the profile reserves (a module's own
    /// outputs).
    void refuse_reserved(const char* key, const image::Range& written) const;
    /// A range in the family's notation.
    std::string format(const image::Range& r) const { return ctx_.naming.format_range(r); }
    /// Describes `devices` as what operand `key` names (BindContext::operands), with `what`
    /// after the key when they are not the operand itself ("value" for a timer's register).
    /// The device getters above describe their operands themselves.
    void note(const char* key, const image::Range& devices, const std::string& what = "") const;
    /// The context the instruction binds in.
    const BindContext& context() const { return ctx_; }

private:
    const Operand* find(const char* key) const;
    /// "D, TN, CN": the family's names of `areas`, leaving out those it does not have.
    std::string names(std::initializer_list<image::Area> areas) const;
    /// The refusal of `text` where `what` of `areas` was expected (see operands.cpp).
    std::string expected(const std::string& what,
                         const std::string& text,
                         const std::optional<image::Device>& d,
                         std::uint32_t n,
                         std::initializer_list<image::Area> areas) const;
    const Operand& require(const char* key);

    const Entry& ic_;
    const BindContext& ctx_;
    const image::Layout& layout_;
    const image::Naming& naming_;
    std::set<std::string> used_;
};

}  // namespace plcemu::instructions
