// libFuzzer harness: the config loader from a config tree, without the YAML library. Input: a
// tree in a small flow syntax → config::read_config (every section, the profile's own sections
// and checks) → daemon::Plc (binding the program) → two scans, checked as config_support.hpp
// says. This is where the loader's rules and the PLC build are fuzzed: fuzz_config covers the
// YAML text in front of the same loader and stops at the config, the YAML library's parse being
// most of its time per input.
//
// The syntax: `{key: value, ...}` a mapping, `[a, b, ...]` a list, `"..."` a scalar as written,
// anything else up to a newline or one of `{}[],:` a scalar (spaces around it dropped), nothing
// at all a null. Every node stands at its first character's line and column. Missing closers
// are taken as read at the end of the input and stray characters are skipped, so most
// mutations of a tree are still a tree. `tests/fuzz/make_corpus.py` writes the seeds from the
// YAML seeds of fuzz_config.

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>

#include "config_support.hpp"
#include "plcemu/config/node.hpp"
#include "plcemu/config/tree.hpp"

using namespace plcemu;

namespace {

using config::Node;

// Deeper inputs are dropped; the YAML front refuses them at the same depth.
constexpr int kMaxDepth = 64;
// How far the reader looks ahead to size a collection (TreeReader::elements).
constexpr std::size_t kLookahead = 1024;

class TreeReader {
public:
    explicit TreeReader(std::string_view in)
        : in_(in) {}

    /// The value at the current position; false in `ok()` when it nests too deeply.
    Node value(int depth) {
        skip_space();
        Node n;
        n.pos = {file_, line_, column()};
        if (depth > kMaxDepth) {
            deep_ = true;
            pos_ = in_.size();
            return n;
        }
        const char c = peek();
        if (c == '{') {
            ++pos_;
            n.kind = Node::Kind::Map;
            n.entries.reserve(elements('}'));
            collection('}', [&] {
                Node key = value(depth + 1);
                skip_space();
                if (peek() == ':') ++pos_;
                Node val = value(depth + 1);
                n.entries.push_back({std::move(key), std::move(val)});
            });
        } else if (c == '[') {
            ++pos_;
            n.kind = Node::Kind::Sequence;
            n.items.reserve(elements(']'));
            collection(']', [&] { n.items.push_back(value(depth + 1)); });
        } else if (c == '"') {
            const std::size_t start = pos_ + 1;
            const std::size_t close = std::min(in_.find('"', start), in_.size());
            n.kind = Node::Kind::Scalar;
            n.text.assign(in_.substr(start, close - start));
            move_to(std::min(close + 1, in_.size()));
        } else {
            std::size_t end = pos_;
            while (end < in_.size() && !special(in_[end])) ++end;
            std::string_view text = in_.substr(pos_, end - pos_);
            while (!text.empty() && (text.back() == ' ' || text.back() == '\t')) {
                text.remove_suffix(1);
            }
            n.text.assign(text);
            n.kind = n.text.empty() ? Node::Kind::Null : Node::Kind::Scalar;
            pos_ = end;  // no newline in between
        }
        return n;
    }

    /// False when the input nests deeper than kMaxDepth.
    bool ok() const { return !deep_; }

private:
    // How many elements the collection just opened holds, counted ahead (commas outside nested
    // collections and quotes, up to `close`), so that its vector is allocated once. A hint: the
    // count looks no further than kLookahead characters, and stray characters may make it low.
    std::size_t elements(char close) const {
        std::size_t commas = 0;
        int nested = 0;
        bool quoted = false;
        bool empty = true;
        const std::size_t end = std::min(in_.size(), pos_ + kLookahead);
        for (std::size_t i = pos_; i < end; ++i) {
            const char c = in_[i];
            if (quoted) {
                quoted = c != '"';
            } else if (c == '"') {
                quoted = true;
            } else if (c == '{' || c == '[') {
                ++nested;
            } else if (c == '}' || c == ']') {
                if (nested == 0) break;  // `close`, or a stray closer the reader skips
                --nested;
            } else if (c == ',' && nested == 0) {
                ++commas;
            }
            if (c != ' ' && c != '\t' && c != '\n' && c != '\r' && c != close) empty = false;
        }
        return empty ? 0 : commas + 1;
    }

    // Elements up to `close`, separated by commas.
    template <class Element>
    void collection(char close, Element element) {
        for (;;) {
            skip_space();
            if (pos_ >= in_.size()) return;
            if (peek() == close) {
                ++pos_;
                return;
            }
            element();
            skip_space();
            if (pos_ >= in_.size()) return;
            if (peek() == close) {
                ++pos_;
                return;
            }
            move_to(pos_ + 1);  // the comma, or a stray character (perhaps a newline)
        }
    }

    static bool special(char c) {
        return c == '{' || c == '}' || c == '[' || c == ']' || c == ',' || c == ':' || c == '\n';
    }
    char peek() const { return pos_ < in_.size() ? in_[pos_] : '\0'; }
    int column() const { return static_cast<int>(pos_ - line_start_) + 1; }
    // Moves on to `to` (at most the end of the input), counting the lines passed.
    void move_to(std::size_t to) {
        for (; pos_ < to; ++pos_) {
            if (in_[pos_] == '\n') {
                ++line_;
                line_start_ = pos_ + 1;
            }
        }
    }
    void skip_space() {
        while (pos_ < in_.size()) {
            const char c = in_[pos_];
            if (c == '\n') {
                ++line_;
                line_start_ = pos_ + 1;
            } else if (c != ' ' && c != '\t' && c != '\r') {
                return;
            }
            ++pos_;
        }
    }

    std::string_view in_;
    // One name for every position, as the YAML reader shares its file's.
    const config::FileName file_{std::string(fuzz::kConfigName)};
    std::size_t pos_ = 0;
    std::size_t line_start_ = 0;  // where the current line starts
    int line_ = 1;
    bool deep_ = false;
};

}  // namespace

extern "C" int LLVMFuzzerInitialize(int* /*argc*/, char*** /*argv*/) {
    fuzz::init_config_harness();
    return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    TreeReader reader({reinterpret_cast<const char*>(data), size});
    const Node root = reader.value(0);
    if (!reader.ok()) return 0;
    fuzz::build_and_run([&] { return config::read_config(root, std::string(fuzz::kConfigName)); });
    return 0;
}
