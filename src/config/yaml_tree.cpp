#include "config/yaml_tree.hpp"

#include <yaml-cpp/eventhandler.h>
#include <yaml-cpp/yaml.h>

#include <cstddef>
#include <cstdint>
#include <istream>
#include <optional>
#include <string>
#include <streambuf>
#include <string_view>
#include <type_traits>
#include <utility>
#include <vector>

#include "plcemu/config/reader.hpp"
#include "plcemu/image/excerpt.hpp"

namespace plcemu::config {

namespace {

// The YAML library's own messages are longer but may quote a character of the file.
constexpr std::size_t kYamlMsgChars = 200;

// A YAML alias shares its node, so a few lines of anchors can stand for an exponential tree: the
// tree stops at a node count and a depth no real config reaches.
constexpr std::size_t kMaxNodes = 1'000'000;
constexpr std::size_t kMaxDepth = 64;

constexpr std::uint32_t kNone = UINT32_MAX;

Position position(const FileName& file, int line, int column) {
    return line < 0 || column < 0 ? Position{file, 1, 1} : Position{file, line + 1, column + 1};
}

[[noreturn]] void too_big(const Position& at) {
    throw ConfigError(at, "the config nests too deeply or repeats too much (more than " +
                              std::to_string(kMaxDepth) + " levels or " +
                              std::to_string(kMaxNodes) + " nodes)");
}

}  // namespace

// The document as the YAML library's parser reports it, kept as its node builder would keep it
// (YAML::Load): a graph in which an alias is the anchored node itself, so that an alias of a
// collection still open makes a cycle. The library's builder allocates several objects per node
// and reference-counts them; this one keeps a small record per node in one vector, the scalars'
// text in one string and the collections' members as links in another vector, which makes
// reading a config about twice as fast (docs/development.md, "Fuzzing") and its records a
// fraction of its tree (docs/performance.md). The limits are kept here already, as the parser
// reports each node: a document nested past them (100,000 flow levels) or larger than them
// stops at the first node past, at its own line and column, before the YAML library's own
// recursion limit or the memory of a huge graph is reached. Offsets are 32 bits: a config file
// is at most 16 MiB (config_file.hpp) and its nodes at most kMaxNodes.
struct YamlDocument::Graph final : public YAML::EventHandler {
    struct Record {
        std::int32_t line = 0;    // the parser's mark, 0-based; negative when it has none
        std::int32_t column = 0;  //
        std::uint32_t text = 0;   // a scalar: where its text starts in `scalars`
        std::uint32_t length = 0;
        std::uint32_t first = kNone;  // a collection: its first link, its last, their number
        std::uint32_t last = kNone;   //   (a mapping's keys and values in turn)
        std::uint32_t size = 0;
        Node::Kind kind = Node::Kind::Null;
        bool quoted = false;  // a scalar in quotes
    };
    // One member of a collection: the record, and the next member's link.
    struct Link {
        std::uint32_t record;
        std::uint32_t next;
    };

    explicit Graph(const std::string& name)
        : file(name) {}

    const FileName file;  // shared by every position made
    std::vector<Record> records;
    std::vector<Link> links;
    std::string scalars;
    std::uint32_t root = kNone;  // none when the text holds no document

    void OnDocumentStart(const YAML::Mark& /*mark*/) override {}
    void OnDocumentEnd() override {}
    void OnNull(const YAML::Mark& mark, YAML::anchor_t anchor) override {
        close(open(Node::Kind::Null, mark, anchor));
    }
    void OnAlias(const YAML::Mark& /*mark*/, YAML::anchor_t anchor) override {
        close(anchors_.at(anchor));
    }
    void OnScalar(const YAML::Mark& mark,
                  const std::string& tag,
                  YAML::anchor_t anchor,
                  const std::string& value) override {
        // A name, a path, a number: no setting takes a NUL (a path would be cut at it).
        if (value.find('\0') != std::string::npos) {
            throw YAML::ParserException(mark, "a NUL character (\\0) in a value");
        }
        const std::uint32_t r = open(Node::Kind::Scalar, mark, anchor);
        records[r].text = static_cast<std::uint32_t>(scalars.size());
        records[r].length = static_cast<std::uint32_t>(value.size());
        scalars += value;
        // yaml-cpp tags a scalar it read without quotes "?", one in quotes "!".
        records[r].quoted = tag == "!";
        close(r);
    }
    void OnSequenceStart(const YAML::Mark& mark,
                         const std::string& /*tag*/,
                         YAML::anchor_t anchor,
                         YAML::EmitterStyle::value /*style*/) override {
        stack_.push_back(open(Node::Kind::Sequence, mark, anchor));
    }
    void OnSequenceEnd() override { end_collection(); }
    void OnMapStart(const YAML::Mark& mark,
                    const std::string& /*tag*/,
                    YAML::anchor_t anchor,
                    YAML::EmitterStyle::value /*style*/) override {
        stack_.push_back(open(Node::Kind::Map, mark, anchor));
    }
    void OnMapEnd() override { end_collection(); }

    Position at(const Record& g) const { return position(file, g.line, g.column); }

    // Calls `each(record)` for a list's items, or `each(key, value)` for a mapping's entries.
    template <class Each>
    void members(const Record& g, Each each) const {
        for (std::uint32_t l = g.first; l != kNone; l = links[l].next) {
            if constexpr (std::is_invocable_v<Each, std::uint32_t>) {
                each(links[l].record);
            } else {
                const std::uint32_t value = links[l].next;
                if (value == kNone) break;
                each(links[l].record, links[value].record);
                l = value;
            }
        }
    }

    // The tree made from record `r` counts `nodes` and reaches `depth`: throws at its first node
    // past the limits, where making it would be (aliases make the tree larger and deeper than
    // the graph).
    void measure(std::uint32_t r, std::size_t depth, std::size_t& nodes) const {
        if (r == kNone) return;
        const Record& g = records[r];
        if (++nodes > kMaxNodes || depth > kMaxDepth) too_big(at(g));
        if (g.kind == Node::Kind::Sequence) {
            members(g, [&](std::uint32_t m) { measure(m, depth + 1, nodes); });
        } else if (g.kind == Node::Kind::Map) {
            members(g, [&](std::uint32_t k, std::uint32_t v) {
                measure(k, depth + 1, nodes);
                measure(v, depth + 1, nodes);
            });
        }
    }

    // The tree of record `r` (measured: within the limits); only the node itself when `bare`.
    Node make(std::uint32_t r, bool bare = false) const {
        Node n;
        if (r == kNone) {
            // No document: a null node at the start of the file.
            n.kind = Node::Kind::Null;
            n.pos = {file, 1, 1};
            return n;
        }
        const Record& g = records[r];
        n.pos = at(g);
        n.kind = g.kind;
        switch (g.kind) {
            case Node::Kind::Scalar:
                n.text.assign(scalars, g.text, g.length);
                n.quoted = g.quoted;
                break;
            case Node::Kind::Sequence:
                if (bare) break;
                n.items.reserve(g.size);
                members(g, [&](std::uint32_t m) { n.items.push_back(make(m)); });
                break;
            case Node::Kind::Map:
                if (bare) break;
                n.entries.reserve(g.size / 2);
                members(g, [&](std::uint32_t k, std::uint32_t v) {
                    Node key = make(k);
                    n.entries.push_back({std::move(key), make(v)});
                });
                break;
            default:
                break;
        }
        return n;
    }

    bool named(std::uint32_t r, std::string_view key) const {
        const Record& g = records[r];
        return g.kind == Node::Kind::Scalar &&
               std::string_view(scalars).substr(g.text, g.length) == key;
    }

    // The tree, the value of the root mapping's first key `key` made without its members when
    // it is a list, whose items are put in `items`.
    Node make_but(std::string_view key, std::vector<std::uint32_t>& items) const {
        items.clear();
        if (root == kNone || records[root].kind != Node::Kind::Map) return make(root);
        const Record& g = records[root];
        Node n = make(root, true);
        n.entries.reserve(g.size / 2);
        bool seen = false;
        members(g, [&](std::uint32_t k, std::uint32_t v) {
            const bool first = !seen && named(k, key);
            seen = seen || first;
            Node name = make(k);
            if (first && records[v].kind == Node::Kind::Sequence) {
                items.reserve(records[v].size);
                members(records[v], [&](std::uint32_t m) { items.push_back(m); });
                n.entries.push_back({std::move(name), make(v, true)});
            } else {
                n.entries.push_back({std::move(name), make(v)});
            }
        });
        return n;
    }

private:
    std::uint32_t open(Node::Kind kind, const YAML::Mark& mark, YAML::anchor_t anchor) {
        // A node's depth is the number of collections open around it, as measure() counts.
        if (records.size() >= kMaxNodes || stack_.size() > kMaxDepth) {
            too_big(position(file, mark.line, mark.column));
        }
        Record g;
        g.line = mark.line;
        g.column = mark.column;
        g.kind = kind;
        records.push_back(g);
        const auto r = static_cast<std::uint32_t>(records.size() - 1);
        // The parser numbers anchors from 1 in the order they appear.
        if (anchor != YAML::NullAnchor) {
            if (anchors_.size() <= anchor) anchors_.resize(anchor + 1, kNone);
            anchors_[anchor] = r;
        }
        return r;
    }
    // Node `r` is complete (or, for an alias, stands where the alias does).
    void close(std::uint32_t r) {
        if (stack_.empty()) {
            root = r;
            return;
        }
        Record& parent = records[stack_.back()];
        const auto l = static_cast<std::uint32_t>(links.size());
        links.push_back({r, kNone});
        if (parent.last == kNone) {
            parent.first = l;
        } else {
            links[parent.last].next = l;
        }
        parent.last = l;
        ++parent.size;
    }
    void end_collection() {
        const std::uint32_t r = stack_.back();
        stack_.pop_back();
        close(r);
    }

    std::vector<std::uint32_t> stack_;    // the collections open
    std::vector<std::uint32_t> anchors_;  // anchor number -> record
};

namespace {

// Refuses the start of a document after the first, at its first token.
struct SecondDocument final : YAML::EventHandler {
    void OnDocumentStart(const YAML::Mark& mark) override {
        throw YAML::ParserException(mark, "a second YAML document: a config file is one document");
    }
    void OnDocumentEnd() override {}
    void OnNull(const YAML::Mark& /*mark*/, YAML::anchor_t /*anchor*/) override {}
    void OnAlias(const YAML::Mark& /*mark*/, YAML::anchor_t /*anchor*/) override {}
    void OnScalar(const YAML::Mark& /*mark*/,
                  const std::string& /*tag*/,
                  YAML::anchor_t /*anchor*/,
                  const std::string& /*value*/) override {}
    void OnSequenceStart(const YAML::Mark& /*mark*/,
                         const std::string& /*tag*/,
                         YAML::anchor_t /*anchor*/,
                         YAML::EmitterStyle::value /*style*/) override {}
    void OnSequenceEnd() override {}
    void OnMapStart(const YAML::Mark& /*mark*/,
                    const std::string& /*tag*/,
                    YAML::anchor_t /*anchor*/,
                    YAML::EmitterStyle::value /*style*/) override {}
    void OnMapEnd() override {}
};

}  // namespace

namespace {

// The line and column (from 1) of the first tab in the leading blanks of a line that holds more
// than blanks, on lines `from` to `last` (from 0); nothing when there is none.
std::optional<std::pair<int, int>> indenting_tab(const std::string& text, int from, int last) {
    int line = 0;
    for (std::size_t start = 0; start < text.size() && line <= last; ++line) {
        std::size_t end = text.find('\n', start);
        if (end == std::string::npos) end = text.size();
        const std::size_t first = text.find_first_not_of(" \t", start);
        if (line >= from && first < end && text[first] != '\r') {
            const std::size_t tab = text.find('\t', start);
            if (tab < first) return std::pair{line + 1, static_cast<int>(tab - start) + 1};
        }
        start = end + 1;
    }
    return std::nullopt;
}

}  // namespace

YamlDocument::YamlDocument(const std::string& text, const std::string& name)
    : graph_(std::make_unique<Graph>(name)) {
    try {
        // The parser reads a stream: this one reads the text where it is (an istringstream
        // would copy it, 5.5 MB for 5,000 PLCs; std::ispanstream is C++23).
        struct TextBuffer : std::streambuf {
            explicit TextBuffer(const std::string& t) {
                char* p = const_cast<char*>(t.data());  // only read: a get area is char*
                setg(p, p, p + t.size());
            }
        } buffer(text);
        std::istream in(&buffer);
        YAML::Parser parser(in);
        parser.HandleNextDocument(*graph_);
        // A config is one document: a second one (after `---`, or `...` and more text) would
        // be dropped unread, and with it whatever it was meant to set.
        SecondDocument second;
        parser.HandleNextDocument(second);
    } catch (const YAML::Exception& e) {
        // The reader's words for a tab in the indentation ("illegal map value", "end of map not
        // found") name neither the tab nor its place. A tab that indents the error's line or
        // the one before is the likely cause, and said beside them (a tab may be legal there,
        // inside a block scalar or a flow collection: the reader's own words stay first).
        std::string why = image::excerpt(e.msg, kYamlMsgChars);
        if (const auto tab = indenting_tab(text, e.mark.line - 1, e.mark.line)) {
            why += " (line " + std::to_string(tab->first) + " is indented with a tab at column ";
            why += std::to_string(tab->second);
            why += ": YAML indents with spaces only)";
        }
        throw ConfigError({name, e.mark.line + 1, e.mark.column + 1}, why);
    }
    std::size_t nodes = 0;
    graph_->measure(graph_->root, 0, nodes);
}

YamlDocument::~YamlDocument() = default;

Node YamlDocument::tree() const { return graph_->make(graph_->root); }

Node YamlDocument::tree_without_items(std::string_view key) {
    return graph_->make_but(key, items_);
}

Node YamlDocument::item(std::size_t i) const { return graph_->make(items_.at(i)); }

Node parse_yaml_tree(const std::string& text, const std::string& name) {
    return YamlDocument(text, name).tree();
}

}  // namespace plcemu::config
