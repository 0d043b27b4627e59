// The YAML document a config is read from (src/config/yaml_tree.hpp): the whole tree, or the
// tree around a `plcs:` list and that list's entries made one at a time, which must be the same
// nodes at the same positions.

#include "config/yaml_tree.hpp"

#include <gtest/gtest.h>

#include <string>

#include "plcemu/config/config.hpp"
#include "plcemu/config/reader.hpp"
#include "support/config_errors.hpp"

namespace plcemu::config {
namespace {

void expect_same_tree(const Node& a, const Node& b) {
    EXPECT_TRUE(a.same(b));
    EXPECT_EQ(a.pos.file.str(), b.pos.file.str());
    EXPECT_EQ(a.pos.line, b.pos.line);
    EXPECT_EQ(a.pos.column, b.pos.column);
    EXPECT_EQ(a.quoted, b.quoted);
    ASSERT_EQ(a.items.size(), b.items.size());
    for (std::size_t i = 0; i < a.items.size(); ++i) expect_same_tree(a.items[i], b.items[i]);
    ASSERT_EQ(a.entries.size(), b.entries.size());
    for (std::size_t i = 0; i < a.entries.size(); ++i) {
        expect_same_tree(a.entries[i].first, b.entries[i].first);
        expect_same_tree(a.entries[i].second, b.entries[i].second);
    }
}

const std::string kPlcs =
    "log: {level: info}\n"
    "plcs:\n"
    "  - {name: a, profile: fbs, init: &seed {R100: [1, 2]}}\n"
    "  - name: b\n"
    "    profile: 'fbs'\n"
    "    init: *seed\n"
    "  - {name: c, profile: vb}\n"
    "http: {port: 8020}\n";

TEST(YamlDocument, EntriesMadeOneAtATimeAreTheWholeTreesEntries) {
    const Node whole = YamlDocument(kPlcs, "p.yaml").tree();
    YamlDocument doc(kPlcs, "p.yaml");
    const Node root = doc.tree_without_items("plcs");
    ASSERT_EQ(doc.items(), 3U);
    // The list stands where it stands, without its items; the keys around it are whole.
    ASSERT_TRUE(root["plcs"].is_sequence());
    EXPECT_TRUE(root["plcs"].items.empty());
    EXPECT_EQ(root["plcs"].pos.line, 3);
    EXPECT_EQ(root["plcs"].pos.column, 3);
    expect_same_tree(root["log"], whole["log"]);
    expect_same_tree(root["http"], whole["http"]);
    for (std::size_t i = 0; i < doc.items(); ++i) {
        SCOPED_TRACE(i);
        expect_same_tree(doc.item(i), whole["plcs"].items[i]);
    }
    // An alias in a later entry of an anchor in an earlier one stands for the anchored node.
    const Node b = doc.item(1);
    EXPECT_EQ(b["init"]["R100"].items.at(1).text, "2");
    EXPECT_EQ(b["init"].pos.line, 3);
    EXPECT_TRUE(b["profile"].quoted);
}

TEST(YamlDocument, WithoutSuchAListTheTreeIsWhole) {
    for (const std::string text : {"plcs: 5\n", "profile: fbs\nstation: 1\n", "[1, 2]\n", ""}) {
        SCOPED_TRACE(text);
        YamlDocument doc(text, "t.yaml");
        expect_same_tree(doc.tree_without_items("plcs"), doc.tree());
        EXPECT_EQ(doc.items(), 0U);
    }
    // Only the first key of that name is left without its items (the loader refuses the
    // second as a duplicate).
    YamlDocument doc("plcs: [a, b]\nplcs: [c]\n", "t.yaml");
    const Node root = doc.tree_without_items("plcs");
    ASSERT_EQ(doc.items(), 2U);
    EXPECT_EQ(doc.item(1).text, "b");
    EXPECT_TRUE(root.entries.at(0).second.items.empty());
    EXPECT_EQ(root.entries.at(1).second.items.at(0).text, "c");
    // The same list aliased under an earlier key keeps its items there.
    YamlDocument aliased("x: &l [a, b]\nplcs: *l\n", "t.yaml");
    const Node r = aliased.tree_without_items("plcs");
    EXPECT_EQ(r["x"].items.size(), 2U);
    EXPECT_TRUE(r["plcs"].items.empty());
    EXPECT_EQ(aliased.items(), 2U);
}

// The limits hold for the whole tree at once, aliases expanded, before any entry is made: an
// alias bomb spread over entries is refused as the whole tree would be, at the same node.
TEST(YamlDocument, LimitsHoldForTheWholeTreeBeforeAnyEntryIsMade) {
    std::string text = "plcs:\n  - a0: &a0 [x, x, x, x, x, x, x, x, x, x]\n";
    for (int i = 1; i < 6; ++i) {
        const std::string p = "*a" + std::to_string(i - 1);
        std::string list = p;
        for (int k = 1; k < 10; ++k) list += ", " + p;
        text += "  - a" + std::to_string(i) + ": &a" + std::to_string(i) + " [" + list + "]\n";
    }
    const testing::ConfigFailure f =
        testing::config_failure([&] { YamlDocument doc(text, "t.yaml"); });
    testing::expect_config_error(f, "t.yaml", 2, 32,
                                 "the config nests too deeply or repeats too much");
    // One entry fewer stays within them.
    const std::string fewer = text.substr(0, text.rfind("  - a5"));
    YamlDocument doc(fewer, "t.yaml");
    EXPECT_EQ(doc.tree_without_items("plcs").size(), 1U);
    EXPECT_EQ(doc.items(), 5U);
}

// Every position read from one file carries one copy of its name, and what the loader keeps of
// them (5,000 PLCs' programs, init entries, sections) shares it too.
TEST(YamlDocument, PositionsShareOneCopyOfTheirFilesName) {
    const Node t = YamlDocument(kPlcs, "p.yaml").tree();
    EXPECT_EQ(&t["log"].pos.file.str(), &t["plcs"].items.at(1)["init"].pos.file.str());
    EXPECT_EQ(t["http"]["port"].pos.file.str(), "p.yaml");
    const Config c = parse_config(
        "profile: fbs\nprogram:\n  - MOV: {en: M0, s: R1, d: R2}\n  - MOV: {en: M0, s: R3, d: "
        "R4}\n",
        "q.yaml");
    ASSERT_EQ(c.program.size(), 2U);
    const std::string& name = c.program[0].pos.file.str();
    EXPECT_EQ(name, "q.yaml");
    EXPECT_EQ(&c.program[1].pos.file.str(), &name);
    EXPECT_EQ(&c.program[1].operands.at(2).second.pos.file.str(), &name);
}

}  // namespace
}  // namespace plcemu::config
