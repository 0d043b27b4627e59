#include "plcemu/config/reader.hpp"

#include <cmath>
#include <set>
#include <sstream>

#include "plcemu/image/excerpt.hpp"

namespace plcemu::config {

namespace {

using image::excerpt;

std::string format_error(const Position& p, const std::string& m) {
    // Line 0: the error is about the file as a whole (e.g. it cannot be opened).
    if (p.line <= 0) return p.file + ": " + m;
    return p.file + ":" + std::to_string(p.line) + ":" + std::to_string(p.column) + ": " + m;
}

}  // namespace

ConfigError::ConfigError(const Position& pos, const std::string& message)
    : std::runtime_error(format_error(pos, message)),
      pos_(pos) {}

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

void Reader::check_keys(const Node& n,
                        const std::string& what,
                        std::initializer_list<const char*> known) const {
    check_keys(n, what, std::vector<std::string>(known.begin(), known.end()));
}

void Reader::check_keys(const Node& n,
                        const std::string& what,
                        const std::vector<std::string>& known) const {
    expect_map(n, what);
    std::set<std::string> seen;
    for (const auto& [k, v] : n.entries) {
        const std::string key = scalar(k, what + " key");
        // A YAML reader keeps the first of two equal keys: a silent surprise, so refuse it.
        if (!seen.insert(key).second) fail(k, "duplicate key '" + excerpt(key) + "' in " + what);
        bool ok = false;
        for (const std::string& name : known) ok = ok || key == name;
        if (ok) continue;
        std::string list;
        for (const std::string& name : known) {
            if (!list.empty()) list += ", ";
            list += name;
        }
        std::string msg = "unknown key '" + excerpt(key) + "' in ";
        msg += what;
        msg += " (expected one of: ";
        msg += list;
        msg += ")";
        fail(k, msg);
    }
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
