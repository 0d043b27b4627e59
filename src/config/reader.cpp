#include "plcemu/config/reader.hpp"

#include <algorithm>
#include <bitset>
#include <cmath>
#include <sstream>
#include <stdexcept>
#include <string_view>
#include <tuple>
#include <utility>

#include "plcemu/image/excerpt.hpp"

namespace plcemu::config {

namespace {

using image::excerpt;

std::string format_error(const Position& p, const std::string& m) {
    // Line 0: the error is about the file as a whole (e.g. it cannot be opened).
    if (p.line <= 0) return p.file.str() + ": " + m;
    const std::string line = std::to_string(p.line);
    const std::string column = std::to_string(p.column);
    std::string out;
    out.reserve(p.file.str().size() + line.size() + column.size() + m.size() + 4);
    out += p.file.str();
    out += ':';
    out += line;
    out += ':';
    out += column;
    out += ": ";
    out += m;
    return out;
}

}  // namespace

namespace {

// The first of a list of errors, which what() shows.
const Diagnostic& first_of(const std::vector<Diagnostic>& errors) {
    if (errors.empty()) throw std::logic_error("ConfigError: no error");
    return errors.front();
}

}  // namespace

ConfigError::ConfigError(const Position& pos, const std::string& message)
    : std::runtime_error(format_error(pos, message)),
      errors_{{pos, message}} {}

ConfigError::ConfigError(std::vector<Diagnostic> errors, bool stopped)
    : std::runtime_error(format_error(first_of(errors).pos, first_of(errors).message)),
      errors_(std::move(errors)),
      stopped_(stopped) {}

std::vector<std::string> ConfigError::lines() const {
    std::vector<std::string> out;
    out.reserve(errors_.size() + 1);
    for (const auto& e : errors_) out.push_back(format_error(e.pos, e.message));
    if (stopped_) {
        out.push_back(format_error(
            {errors_.front().pos.file, 0, 0},
            "too many errors, stopped after the " + std::to_string(errors_.size()) + " above"));
    }
    return out;
}

ConfigError ConfigError::prefixed(const std::string& prefix) const {
    std::vector<Diagnostic> errors = errors_;
    for (auto& e : errors) e.message.insert(0, prefix);
    return ConfigError(std::move(errors), stopped_);
}

void Errors::add(const ConfigError& e) {
    for (const auto& d : e.errors()) {
        if (list_.size() == kMax) {
            stopped_ = true;
            break;
        }
        list_.push_back({d.pos, prefix_ + d.message});
    }
    if (e.stopped()) stopped_ = true;
    if (stopped_) raise();
}

void Errors::raise() const {
    if (list_.empty()) return;
    // In the order of the file, as a compiler lists them, whatever order the sections are read in.
    std::vector<Diagnostic> sorted = list_;
    std::stable_sort(sorted.begin(), sorted.end(), [](const Diagnostic& a, const Diagnostic& b) {
        return std::tie(a.pos.line, a.pos.column) < std::tie(b.pos.line, b.pos.column);
    });
    throw ConfigError(std::move(sorted), stopped_);
}

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

void Reader::report(const Node& n, const std::string& msg) const {
    if (errors_ == nullptr) fail(n, msg);
    errors_->add(ConfigError(n.pos, msg));
}

void Reader::expect_map(const Node& n, const std::string& what) const {
    if (!n.is_map()) fail(n, what + ": expected a mapping");
}

namespace {

// Every mapping of a config goes through here: nothing is allocated unless a key is refused. A
// key is either one of `known` (at most once) or refused where it stands; a reader with Errors
// records each refused key and goes on with the next.
template <class Names>
void check_known_keys(const Reader& r, const Node& n, const std::string& what, const Names& known) {
    r.expect_map(n, what);
    constexpr std::size_t kMaxNames = 64;
    if (known.size() > kMaxNames) throw std::logic_error("check_keys: too many names");
    std::bitset<kMaxNames> seen;
    for (const auto& [k, v] : n.entries) {
        if (!k.is_scalar()) {
            r.report(k, what + " key: expected a scalar");
            continue;
        }
        const std::string& key = k.text;
        std::size_t i = 0;
        for (const auto& name : known) {
            if (key == name) break;
            ++i;
        }
        if (i < known.size()) {
            // A YAML reader keeps the first of two equal keys: a silent surprise, so refuse it.
            if (seen[i]) r.report(k, "duplicate key '" + excerpt(key) + "' in " + what);
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
        r.report(k, msg);
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
    bool too_large = false;
    if (!naming_->parse_integer(s, v, &too_large) && !too_large)
        fail(n, what + ": expected an integer, got '" + excerpt(s) + "'");
    if (too_large || v < lo || v > hi) {
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
