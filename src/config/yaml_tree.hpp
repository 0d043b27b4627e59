#pragma once
// The loader's first half: YAML text to a config tree (plcemu/config/node.hpp).

#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include "plcemu/config/node.hpp"

namespace plcemu::config {

/// One YAML document as the parser reported it, from which trees are made: the whole tree, or
/// (a `plcs:` file of thousands of entries) the tree around one list and that list's items one
/// at a time, so that the entries never stand all at once as trees.
class YamlDocument {
public:
    /// Reads the first YAML document of `text`, its positions naming `name`. Throws ConfigError
    /// at the position of a YAML syntax error, or of the first node of the tree (aliases
    /// expanded: they may stand for an exponential tree) past the nesting and size limits.
    YamlDocument(const std::string& text, const std::string& name);
    ~YamlDocument();
    YamlDocument(const YamlDocument&) = delete;
    YamlDocument& operator=(const YamlDocument&) = delete;

    /// The whole document as a tree; an empty text is a null node at 1:1.
    Node tree() const;
    /// The tree with the list under the root mapping's first key `key` standing without its
    /// items, which items() counts and item() makes one at a time (the whole tree, and no
    /// items, when the root holds no such list).
    Node tree_without_items(std::string_view key);
    /// The items of the list tree_without_items() left out.
    std::size_t items() const { return items_.size(); }
    /// Item `i` (< items()) of that list as a tree.
    Node item(std::size_t i) const;

private:
    struct Graph;
    std::unique_ptr<Graph> graph_;
    std::vector<std::uint32_t> items_;  // the records of the list's items
};

/// The first YAML document of `text` as a tree whose positions name `name` (YamlDocument::tree).
Node parse_yaml_tree(const std::string& text, const std::string& name);

}  // namespace plcemu::config
