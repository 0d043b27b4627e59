#include "config/yaml_tree.hpp"

#include <yaml-cpp/eventhandler.h>
#include <yaml-cpp/yaml.h>

#include <cstddef>
#include <sstream>
#include <vector>

#include "plcemu/config/reader.hpp"
#include "plcemu/image/excerpt.hpp"

namespace plcemu::config {

namespace {

// The YAML library's own messages are longer but may quote a character of the file.
constexpr std::size_t kYamlMsgChars = 200;

// A YAML alias shares its node, so a few lines of anchors can stand for an exponential tree: the
// copy stops at a node count and a depth no real config reaches.
constexpr std::size_t kMaxNodes = 1'000'000;
constexpr std::size_t kMaxDepth = 64;

Position position(const std::string& file, const YAML::Mark& mark) {
    return mark.line < 0 || mark.column < 0 ? Position{file, 1, 1}
                                            : Position{file, mark.line + 1, mark.column + 1};
}

[[noreturn]] void too_big(const Position& at) {
    throw ConfigError(at, "the config nests too deeply or repeats too much (more than " +
                              std::to_string(kMaxDepth) + " levels or " +
                              std::to_string(kMaxNodes) + " nodes)");
}

// The document as the YAML library's parser reports it, kept as its node builder would keep it
// (YAML::Load): a graph in which an alias is the anchored node itself, so that an alias of a
// collection still open makes a cycle. The library's builder allocates several objects per node
// and reference-counts them; this one keeps one record per node in a single vector, which makes
// reading a config about twice as fast (docs/development.md, "Fuzzing"). The limits are kept
// here already, as the parser reports each node: a document nested past them (100,000 flow
// levels) or larger than them stops at the first node past, at its own line and column, before
// the YAML library's own recursion limit or the memory of a huge graph is reached.
class Graph final : public YAML::EventHandler {
public:
    static constexpr std::size_t kNone = static_cast<std::size_t>(-1);

    explicit Graph(const std::string& file)
        : file_(file) {}

    struct Record {
        Node::Kind kind = Node::Kind::Null;
        YAML::Mark mark;
        std::string text;                  // a scalar
        std::vector<std::size_t> members;  // a list's items; a mapping's keys and values in turn
        bool quoted = false;               // a scalar in quotes
    };

    std::vector<Record> records;
    std::size_t root = kNone;  // none when the text holds no document

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
        const std::size_t r = open(Node::Kind::Scalar, mark, anchor);
        records[r].text = value;
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

private:
    std::size_t open(Node::Kind kind, const YAML::Mark& mark, YAML::anchor_t anchor) {
        // A node's depth is the number of collections open around it, as TreeBuilder counts.
        if (records.size() >= kMaxNodes || stack_.size() > kMaxDepth) {
            too_big(position(file_, mark));
        }
        records.push_back({kind, mark, {}, {}, false});
        const std::size_t r = records.size() - 1;
        // The parser numbers anchors from 1 in the order they appear.
        if (anchor != YAML::NullAnchor) {
            if (anchors_.size() <= anchor) anchors_.resize(anchor + 1, kNone);
            anchors_[anchor] = r;
        }
        return r;
    }
    // Node `r` is complete (or, for an alias, stands where the alias does).
    void close(std::size_t r) {
        if (stack_.empty()) {
            root = r;
        } else {
            records[stack_.back()].members.push_back(r);
        }
    }
    void end_collection() {
        const std::size_t r = stack_.back();
        stack_.pop_back();
        close(r);
    }

    const std::string& file_;
    std::vector<std::size_t> stack_;    // the collections open
    std::vector<std::size_t> anchors_;  // anchor number -> record
};

// The graph as a plain tree, within the same limits: aliases make the tree larger and deeper than
// the graph.
struct TreeBuilder {
    const Graph& graph;
    const std::string& file;
    std::size_t nodes = 0;

    Node operator()(std::size_t r, std::size_t depth) {
        Node n;
        if (r == Graph::kNone) {
            // No document: a null node at the start of the file.
            n.kind = Node::Kind::Null;
            n.pos = {file, 1, 1};
            return n;
        }
        const Graph::Record& g = graph.records[r];
        n.pos = position(file, g.mark);
        if (++nodes > kMaxNodes || depth > kMaxDepth) too_big(n.pos);
        n.kind = g.kind;
        switch (g.kind) {
            case Node::Kind::Scalar:
                n.text = g.text;
                n.quoted = g.quoted;
                break;
            case Node::Kind::Sequence:
                n.items.reserve(g.members.size());
                for (const std::size_t m : g.members) n.items.push_back((*this)(m, depth + 1));
                break;
            case Node::Kind::Map:
                n.entries.reserve(g.members.size() / 2);
                for (std::size_t i = 0; i + 1 < g.members.size(); i += 2) {
                    Node key = (*this)(g.members[i], depth + 1);
                    n.entries.push_back({std::move(key), (*this)(g.members[i + 1], depth + 1)});
                }
                break;
            default:
                break;
        }
        return n;
    }
};

}  // namespace

Node parse_yaml_tree(const std::string& text, const std::string& name) {
    Graph graph(name);
    try {
        std::istringstream in(text);
        YAML::Parser parser(in);
        parser.HandleNextDocument(graph);
    } catch (const YAML::Exception& e) {
        throw ConfigError({name, e.mark.line + 1, e.mark.column + 1},
                          image::excerpt(e.msg, kYamlMsgChars));
    }
    TreeBuilder build{graph, name};
    return build(graph.root, 0);
}

}  // namespace plcemu::config
