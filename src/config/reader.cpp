#include "plcemu/config/reader.hpp"

#include <bitset>
#include <cmath>
#include <sstream>
#include <stdexcept>
#include <string_view>

#include "plcemu/image/excerpt.hpp"

namespace plcemu::config {

namespace {

using image::excerpt;

std::string format_error(const Position& p, const std::string& m) {
    // Line 0: the error is about the file as a whole (e.g. it cannot be opened).
    if (p.line <= 0) return p.file + ": " + m;
    const std::string line = std::to_string(p.line);
    const std::string column = std::to_string(p.column);
    std::string out;
    out.reserve(p.file.size() + line.size() + column.size() + m.size() + 4);
    out += p.file;
    out += ':';
    out += line;
    out += ':';
    out += column;
    out += ": ";
    out += m;
    return out;
}

}  // namespace

ConfigError::ConfigError(const Position& pos, const std::string& message)
    : std::runtime_error(format_error(pos, message)),
      pos_(pos),
      message_(message) {}

const Node& Node::operator[](std::string_view key) const {
    static const Node kAbsent;
    if (kind != Kind::Map) return kAbsent;
    for (const auto& [k, v] : entries) {
        if (k.kind == Kind::Scalar && k.text == key) return v;
    }
    return kAbsent;
}

bool Node::same(const Node& o) const {
    if (kind != o.kind || text != o.text || items.size() != o.items.size() ||
        entries.size() != o.entries.size()) {
        return false;
    }
    for (std::size_t i = 0; i < items.size(); ++i) {
        if (!items[i].same(o.items[i])) return false;
    }
    for (std::size_t i = 0; i < entries.size(); ++i) {
        if (!entries[i].first.same(o.entries[i].first) ||
            !entries[i].second.same(o.entries[i].second)) {
            return false;
        }
    }
    return true;
}

std::string Reader::octal_hint(const std::string& text) const {
    const std::string why = naming_->why_not(text);
    return why.empty() ? "" : " (" + why + ")";
}

void Reader::fail(const Node& n, const std::string& msg) const { throw ConfigError(n.pos, msg); }

void Reader::expect_map(const Node& n, const std::string& what) const {
    if (!n.is_map()) fail(n, what + ": expected a mapping");
}

namespace {

// Every mapping of a config goes through here: nothing is allocated unless a key is refused. A
// key is either one of `known` (at most once) or refused where it first stands, so the first
// refused key is the one a check of duplicates before names would find.
template <class Names>
void check_known_keys(const Reader& r, const Node& n, const std::string& what, const Names& known) {
    r.expect_map(n, what);
    constexpr std::size_t kMaxNames = 64;
    if (known.size() > kMaxNames) throw std::logic_error("check_keys: too many names");
    std::bitset<kMaxNames> seen;
    for (const auto& [k, v] : n.entries) {
        if (!k.is_scalar()) r.scalar(k, what + " key");  // refuses it
        const std::string& key = k.text;
        std::size_t i = 0;
        for (const auto& name : known) {
            if (key == name) break;
            ++i;
        }
        if (i < known.size()) {
            // A YAML reader keeps the first of two equal keys: a silent surprise, so refuse it.
            if (seen[i]) r.fail(k, "duplicate key '" + excerpt(key) + "' in " + what);
            seen[i] = true;
            continue;
        }
        // Built in one piece: mistyped keys are most of what a fuzzer tries.
        const std::string quoted = excerpt(key);
        std::size_t length = quoted.size() + what.size() + 48;
        for (const auto& name : known) length += std::string_view(name).size() + 2;
        std::string msg;
        msg.reserve(length);
        msg += "unknown key '";
        msg += quoted;
        msg += "' in ";
        msg += what;
        msg += " (expected one of: ";
        bool first = true;
        for (const auto& name : known) {
            if (!first) msg += ", ";
            first = false;
            msg += name;
        }
        msg += ")";
        r.fail(k, msg);
    }
}

}  // namespace

void Reader::check_keys(const Node& n,
                        const std::string& what,
                        std::initializer_list<const char*> known) const {
    check_known_keys(*this, n, what, known);
}

void Reader::check_keys(const Node& n,
                        const std::string& what,
                        const std::vector<std::string>& known) const {
    check_known_keys(*this, n, what, known);
}

std::string Reader::scalar(const Node& n, const std::string& what) const {
    if (!n.is_scalar()) fail(n, what + ": expected a scalar");
    return n.text;
}

long long Reader::integer(const Node& n,
                          const std::string& what,
                          long long lo,
                          long long hi) const {
    const std::string s = scalar(n, what);
    long long v = 0;
    if (!naming_->parse_integer(s, v))
        fail(n, what + ": expected an integer, got '" + excerpt(s) + "'");
    if (v < lo || v > hi) {
        fail(n, what + ": " + excerpt(s) + " is out of range " + std::to_string(lo) + ".." +
                    std::to_string(hi));
    }
    return v;
}

double Reader::number(const Node& n, const std::string& what, double lo, double hi) const {
    const std::string s = scalar(n, what);
    double v = 0;
    std::istringstream is(s);
    is >> v;
    if (!is || !is.eof() || !std::isfinite(v)) {
        fail(n, what + ": expected a number, got '" + excerpt(s) + "'");
    }
    if (v < lo || v > hi) {
        std::ostringstream o;
        o << what << ": " << excerpt(s) << " is out of range " << lo << ".." << hi;
        fail(n, o.str());
    }
    return v;
}

bool Reader::boolean(const Node& n, const std::string& what) const {
    const std::string s = scalar(n, what);
    if (s == "true" || s == "yes" || s == "on" || s == "1") return true;
    if (s == "false" || s == "no" || s == "off" || s == "0") return false;
    fail(n, what + ": expected true or false, got '" + excerpt(s) + "'");
}

image::Device Reader::device(const Node& n, const std::string& what) const {
    const std::string s = scalar(n, what);
    auto d = naming_->parse_device(s);
    if (!d) fail(n, what + ": '" + excerpt(s) + "' is not a device of this PLC" + octal_hint(s));
    return *d;
}

image::Range Reader::range(const Node& n, const std::string& what) const {
    const std::string s = scalar(n, what);
    auto r = naming_->parse_range(s);
    if (!r) {
        fail(n, what + ": expected a device range such as D100-D199, got '" + excerpt(s) + "'" +
                    octal_hint(s));
    }
    return *r;
}

}  // namespace plcemu::config
