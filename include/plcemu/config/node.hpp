#pragma once
// A configuration file as a plain tree: what the YAML said, each node with its position, and
// nothing of the YAML library. The loader reads the common sections from it; a profile reads
// its own sections (config::Config::sections) with the same Reader.

#include <cstdint>
#include <memory>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

namespace plcemu::config {

/// A file's name as positions carry it: one copy, shared by every position read from the file
/// (5,000 PLCs' configs hold hundreds of thousands of positions, docs/performance.md).
class FileName {
public:
    FileName() = default;
    FileName(std::string name)  // NOLINT(google-explicit-constructor): a name is a file name
        : name_(std::make_shared<const std::string>(std::move(name))) {}
    FileName(const char* name)  // NOLINT(google-explicit-constructor)
        : FileName(std::string(name)) {}
    /// The name; "" when none was given.
    const std::string& str() const noexcept {
        static const std::string none;
        return name_ ? *name_ : none;
    }

private:
    std::shared_ptr<const std::string> name_;
};

/// Where something stands in a config file (1-based line and column).
struct Position {
    FileName file;   ///< file name as given
    int line = 0;    ///< 1-based line
    int column = 0;  ///< 1-based column
};

/// One node of a config file.
class Node {
public:
    /// What the node is.
    enum class Kind : std::uint8_t {
        Undefined,  ///< not in the file (a key that is absent)
        Null,       ///< `key:` with nothing after it
        Scalar,     ///< a scalar, as written
        Sequence,   ///< a list
        Map,        ///< a mapping
    };

    struct Entry;  ///< a mapping's key and value

    Kind kind = Kind::Undefined;  ///< what it is
    std::string text;             ///< the scalar, as written
    Position pos;                 ///< where it stands
    /// A scalar written in quotes (or as a block): its first character stands one column
    /// after `pos`, which is the quote's.
    bool quoted = false;
    std::vector<Node> items;     ///< a list's items
    std::vector<Entry> entries;  ///< a mapping's keys and values, in file order

    /// True unless the node is absent.
    explicit operator bool() const { return kind != Kind::Undefined; }
    bool is_null() const { return kind == Kind::Null; }          ///< `key:` alone
    bool is_scalar() const { return kind == Kind::Scalar; }      ///< a scalar
    bool is_sequence() const { return kind == Kind::Sequence; }  ///< a list
    bool is_map() const { return kind == Kind::Map; }            ///< a mapping
    /// Items of a list, entries of a mapping.
    std::size_t size() const;
    /// The value of the first key `key` of a mapping; an Undefined node when there is none (or
    /// this is not a mapping).
    const Node& operator[](std::string_view key) const;
    /// True when both say the same, wherever they stand (a reload compares sections so).
    bool same(const Node& other) const;
};

/// One key of a mapping with its value.
struct Node::Entry {
    Node first;   ///< the key
    Node second;  ///< its value
};

inline std::size_t Node::size() const { return is_map() ? entries.size() : items.size(); }

}  // namespace plcemu::config
