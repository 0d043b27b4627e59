// libFuzzer harness: the config loader from a config tree, without the YAML library. Input: a
// tree in a small flow syntax → config::read_config (every section, the profile's own sections
// and checks) → daemon::Plc (binding the program) → two scans, checked as config_support.hpp
// says. fuzz_config covers the YAML text in front of the same loader, at a tenth of the speed:
// the YAML library's parse is most of its time per input.
//
// The syntax: `{key: value, ...}` a mapping, `[a, b, ...]` a list, `"..."` a scalar as written,
// anything else up to a newline or one of `{}[],:` a scalar (spaces around it dropped), nothing
// at all a null. Every node stands at its first character's line and column. Missing closers
// are taken as read at the end of the input and stray characters are skipped, so most
// mutations of a tree are still a tree. `tests/fuzz/make_corpus.py` writes the seeds from the
// YAML seeds of fuzz_config.

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

class TreeReader {
public:
    explicit TreeReader(std::string_view in)
        : in_(in) {}

    /// The value at the current position; false in `ok()` when it nests too deeply.
    Node value(int depth) {
        skip_space();
        Node n;
        n.pos = {std::string(fuzz::kConfigName), line_, column_};
        if (depth > kMaxDepth) {
            deep_ = true;
            pos_ = in_.size();
            return n;
        }
        const char c = peek();
        if (c == '{') {
            advance();
            n.kind = Node::Kind::Map;
            collection('}', [&] {
                Node key = value(depth + 1);
                skip_space();
                if (peek() == ':') advance();
                Node val = value(depth + 1);
                n.entries.push_back({std::move(key), std::move(val)});
            });
        } else if (c == '[') {
            advance();
            n.kind = Node::Kind::Sequence;
            collection(']', [&] { n.items.push_back(value(depth + 1)); });
        } else if (c == '"') {
            advance();
            n.kind = Node::Kind::Scalar;
            while (pos_ < in_.size() && peek() != '"') n.text += take();
            if (pos_ < in_.size()) advance();
        } else {
            while (pos_ < in_.size() && !special(peek())) n.text += take();
            while (!n.text.empty() && (n.text.back() == ' ' || n.text.back() == '\t')) {
                n.text.pop_back();
            }
            n.kind = n.text.empty() ? Node::Kind::Null : Node::Kind::Scalar;
        }
        return n;
    }

    /// False when the input nests deeper than kMaxDepth.
    bool ok() const { return !deep_; }

private:
    // Elements up to `close`, separated by commas.
    template <class Element>
    void collection(char close, Element element) {
        for (;;) {
            skip_space();
            if (pos_ >= in_.size()) return;
            if (peek() == close) {
                advance();
                return;
            }
            element();
            skip_space();
            if (pos_ >= in_.size()) return;
            if (peek() == close) {
                advance();
                return;
            }
            advance();  // the comma, or a stray character
        }
    }

    static bool special(char c) {
        return c == '{' || c == '}' || c == '[' || c == ']' || c == ',' || c == ':' || c == '\n';
    }
    char peek() const { return pos_ < in_.size() ? in_[pos_] : '\0'; }
    char take() {
        const char c = peek();
        advance();
        return c;
    }
    void advance() {
        if (pos_ >= in_.size()) return;
        if (in_[pos_] == '\n') {
            ++line_;
            column_ = 1;
        } else {
            ++column_;
        }
        ++pos_;
    }
    void skip_space() {
        while (pos_ < in_.size() &&
               (peek() == ' ' || peek() == '\t' || peek() == '\n' || peek() == '\r')) {
            advance();
        }
    }

    std::string_view in_;
    std::size_t pos_ = 0;
    int line_ = 1;
    int column_ = 1;
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
