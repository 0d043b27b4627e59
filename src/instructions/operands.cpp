#include "operands.hpp"

#include <algorithm>
#include <string_view>

#include "plcemu/image/excerpt.hpp"

namespace plcemu::instructions {

namespace {

bool among(image::Area a, std::initializer_list<image::Area> areas) {
    return std::find(areas.begin(), areas.end(), a) != areas.end();
}

}  // namespace

Operands::Operands(const Entry& ic, const BindContext& ctx)
    : ic_(ic),
      ctx_(ctx),
      layout_(ctx.layout),
      naming_(ctx.naming) {}

void Operands::note(const char* key, const image::Range& devices, const std::string& what) const {
    if (ctx_.operands == nullptr) return;
    const Operand* op = find(key);
    const std::string named = what.empty() ? std::string(key) : std::string(key) + " " + what;
    ctx_.operands->push_back({devices, ic_.mnemonic + " " + named + ", " + ic_.ordinal() + " (" +
                                           (op ? op->where : ic_.where).text() + ")"});
}

void Operands::refuse_reserved(const char* key, const image::Range& written) const {
    for (const auto& [range, why] : ctx_.services.reserved_outputs) {
        if (written.overlaps(range)) {
            fail(key, format(written) + " overlaps " + format(range) + ", " + why);
        }
    }
}

const Operand* Operands::find(const char* key) const {
    for (const auto& [k, v] : ic_.operands) {
        if (k == key) return &v;
    }
    return nullptr;
}

bool Operands::has(const char* key) const { return find(key) != nullptr; }

std::optional<long long> Operands::constant(const char* key) const {
    const Operand* op = find(key);
    long long v = 0;
    // A device name wins; anything else that parses is a constant (0x1F, 1Fh and K31 too).
    if (op == nullptr || naming_.parse_device(op->text) || !naming_.parse_integer(op->text, v)) {
        return std::nullopt;
    }
    return v;
}

bool Operands::numeric(const char* key) const {
    if (constant(key)) return true;
    const Operand* op = find(key);
    long long v = 0;
    bool too_large = false;
    return op != nullptr && !naming_.parse_integer(op->text, v, &too_large) && too_large;
}

void Operands::fail(const char* key, const std::string& message) const {
    const Operand* op = find(key);
    std::string text = image::excerpt(ic_.mnemonic) + "." + key + ": " + message;
    // X8 on a VB: say that X and Y count in octal, as the config loader does.
    const std::string why = op ? naming_.why_not(op->text) : "";
    if (!why.empty()) text += " (" + why + ")";
    throw BindError(op ? op->where : ic_.where, text);
}

const Operand& Operands::require(const char* key) {
    used_.insert(key);
    const Operand* op = find(key);
    if (!op) fail(key, "operand is required");
    return *op;
}

BitSource Operands::bit_source(const char* key, bool fallback) {
    used_.insert(key);
    const Operand* op = find(key);
    // In a listing the rung gives the enable (the listing refuses an `en` written out).
    if (!op && ctx_.rung != nullptr && std::string_view(key) == "en") {
        return {false, false, {}, ctx_.rung};
    }
    if (!op) return {true, fallback, {}};
    if (const auto v = constant(key)) {
        if (*v != 0 && *v != 1) fail(key, "a constant enable must be 0 or 1");
        return {true, *v == 1, {}};
    }
    auto d = naming_.parse_device(op->text);
    if (!d || d->word_of_bits || !layout_.contains({d->area, d->index, 1})) {
        fail(key, "expected a bit device (X, Y, M, S, T, C) or 0/1, got '" +
                      image::excerpt(op->text) + "'");
    }
    if (!image::is_bit_area(d->area))
        fail(key, "expected a bit device, got '" + image::excerpt(op->text) + "'");
    note(key, {d->area, d->index, 1});
    return {false, false, *d};
}

image::Device Operands::bit_output(const char* key) {
    const auto& op = require(key);
    auto d = naming_.parse_device(op.text);
    if (!d || d->word_of_bits ||
        !(d->area == image::Area::Y || d->area == image::Area::M || d->area == image::Area::S) ||
        !layout_.contains({d->area, d->index, 1})) {
        fail(key, "expected a Y, M or S output, got '" + image::excerpt(op.text) + "'");
    }
    refuse_reserved(key, {d->area, d->index, 1});
    note(key, {d->area, d->index, 1});
    return *d;
}

std::optional<image::Device> Operands::optional_bit_output(const char* key) {
    if (!has(key)) return std::nullopt;
    return bit_output(key);
}

WordSource Operands::word_source(const char* key) {
    const auto& op = require(key);
    if (const auto v = constant(key)) {
        if (*v < -32768 || *v > 65535) fail(key, "constant out of 16-bit range");
        return {true, static_cast<std::uint16_t>(*v & 0xFFFF), {}};
    }
    auto d = naming_.parse_device(op.text);
    if (!d) {
        // A number too large for any integer is a constant out of range as well.
        if (numeric(key)) fail(key, "constant out of 16-bit range");
        // The family's own register names: a VB has no R, and spells timer values TN.
        fail(key, "expected a register (" +
                      names({image::Area::R, image::Area::D, image::Area::TV, image::Area::CV}) +
                      "), WMn-style bits or a constant, got '" + image::excerpt(op.text) + "'");
    }
    const std::uint32_t span = d->word_of_bits ? 16 : 1;
    if ((!d->word_of_bits && image::is_bit_area(d->area)) ||
        !layout_.contains({d->area, d->index, span})) {
        // Built by appending: GCC 12 at -O2 takes the inlined inserts of `"..." + std::string`
        // here for overlapping copies (-Wrestrict, a false positive).
        std::string msg = "'";
        msg += image::excerpt(op.text);
        msg += "' is not a word operand of this PLC";
        // The manuals write a timer's or counter's value with the contact's name ("< T200
        // D102"); say how this family spells it.
        if (!d->word_of_bits && (d->area == image::Area::T || d->area == image::Area::C)) {
            const bool timer = d->area == image::Area::T;
            const image::Area value = timer ? image::Area::TV : image::Area::CV;
            const std::uint32_t word = timer ? d->index : naming_.counter_word(d->index);
            if (!naming_.area_name(value).empty() && layout_.contains({value, word, 1})) {
                msg += " (its value is ";
                msg += naming_.format_device(value, word);
                msg += ')';
            }
        }
        fail(key, msg);
    }
    note(key, {d->area, d->index, span});
    return {false, 0, *d};
}

image::Device Operands::word_output(const char* key) {
    using image::Area;
    return output_words(key, 1, {Area::R, Area::D, Area::M, Area::Y, Area::S, Area::TV, Area::CV});
}

image::Device Operands::output_words(const char* key,
                                     std::uint32_t span,
                                     std::initializer_list<image::Area> areas) {
    const image::Device d = word_device(key, span, areas);
    refuse_reserved(key, {d.area, d.index, d.word_of_bits ? 16 * span : span});
    return d;
}

image::Device Operands::word_device(const char* key,
                                    std::uint32_t span,
                                    std::initializer_list<image::Area> areas) {
    const auto& op = require(key);
    auto d = naming_.parse_device(op.text);
    bool ok = d.has_value();
    if (ok) {
        const std::uint32_t n = d->word_of_bits ? 16 * span : span;
        ok = among(d->area, areas) && (d->word_of_bits || !image::is_bit_area(d->area)) &&
             layout_.contains({d->area, d->index, n});
    }
    if (!ok) {
        const std::uint32_t n = d && d->word_of_bits ? 16 * span : span;
        fail(key, expected(std::to_string(span) + " word(s)", op.text, d, n, areas));
    }
    note(key, {d->area, d->index, d->word_of_bits ? 16 * span : span});
    return *d;
}

// "expected 10 word(s) in R, D, got 'R8065'", and ": R8065-R8074 go past the last R, R8071"
// when `d`, read from `text`, is a device of one of `areas` whose `n` devices run past its
// area's end.
std::string Operands::expected(const std::string& what,
                               const std::string& text,
                               const std::optional<image::Device>& d,
                               std::uint32_t n,
                               std::initializer_list<image::Area> areas) const {
    std::string out = "expected " + what + " in " + names(areas);
    out += ", got '";
    out += image::excerpt(text);
    out += '\'';
    if (!d) return out;
    const std::uint32_t size = layout_.size_of(d->area);
    if (!among(d->area, areas) || n < 2 || d->index >= size || d->index + n <= size) return out;
    out += ": ";
    out += naming_.format_range({d->area, d->index, n});
    out += " go past ";
    out += naming_.last_of(d->area, size);
    return out;
}

image::Device Operands::device(const char* key,
                               std::uint32_t span,
                               std::initializer_list<image::Area> areas) {
    const auto& op = require(key);
    auto d = naming_.parse_device(op.text);
    bool ok = d.has_value() && !d->word_of_bits;
    if (ok) {
        ok = among(d->area, areas) && layout_.contains({d->area, d->index, span});
    }
    if (!ok) {
        // A word of bits is no run of devices: nothing of it goes past anything.
        if (d && d->word_of_bits) d.reset();
        fail(key,
             expected(std::to_string(span) + " consecutive device(s)", op.text, d, span, areas));
    }
    note(key, {d->area, d->index, span});
    return *d;
}

long long Operands::integer(const char* key, long long lo, long long hi) {
    const auto& op = require(key);
    long long v = 0;
    bool too_large = false;
    const bool read = naming_.parse_integer(op.text, v, &too_large);
    if (!read && !too_large)
        fail(key, "expected an integer, got '" + image::excerpt(op.text) + "'");
    if (!read || v < lo || v > hi) {
        fail(key, image::excerpt(op.text) + " is out of range " + std::to_string(lo) + ".." +
                      std::to_string(hi));
    }
    return v;
}

bool Operands::flag(const char* key, bool fallback) {
    used_.insert(key);
    const Operand* op = find(key);
    if (!op) return fallback;
    const std::string& t = op->text;
    if (t == "true" || t == "yes" || t == "on" || t == "1") return true;
    if (t == "false" || t == "no" || t == "off" || t == "0") return false;
    fail(key, "expected true or false, got '" + image::excerpt(t) + "'");
}

std::string Operands::names(std::initializer_list<image::Area> areas) const {
    std::string out;
    for (auto a : areas) {
        if (naming_.area_name(a).empty()) continue;
        out += std::string(out.empty() ? "" : ", ") + std::string(naming_.area_name(a));
    }
    return out;
}

void Operands::finish() const {
    for (const auto& [k, v] : ic_.operands) {
        if (!used_.count(k)) {
            throw BindError(v.where, image::excerpt(ic_.mnemonic) + ": unknown operand '" +
                                         image::excerpt(k) + "'");
        }
    }
}

}  // namespace plcemu::instructions
