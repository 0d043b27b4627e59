// What a reload compares to find the `plcs:` entries that did not change (docs/operations.md,
// "Reload (SIGHUP)"): each PLC's config summed as written, wherever it stands in the file.

#include <gtest/gtest.h>

#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "plcemu/config/config.hpp"

namespace plcemu::config {
namespace {

std::vector<Config> plcs(const std::string& text, const std::string& name = "t.yaml") {
    return parse_plcs(text, name);
}

const std::string kTwo =
    "plcs:\n"
    "  - {name: a, profile: fbs, modbus: {tcp: {port: 5020}}}\n"
    "  - name: b\n"
    "    profile: fbs\n"
    "    modbus: {tcp: {port: 5021}}\n"
    "    init: {R100: 7}\n";

TEST(ConfigFingerprint, LinesMovedAndCommentsChangeNothing) {
    const auto before = plcs(kTwo);
    const auto after = plcs("# a comment that moves every line\n\n" + kTwo + "# and one last\n");
    ASSERT_EQ(before.size(), 2u);
    EXPECT_EQ(before[0].fingerprint, after[0].fingerprint);
    EXPECT_EQ(before[1].fingerprint, after[1].fingerprint);
    EXPECT_NE(before[0].fingerprint, before[1].fingerprint);
    EXPECT_NE(before[0].fingerprint, Fingerprint{});
}

TEST(ConfigFingerprint, AValueChangesOnlyItsOwnEntry) {
    const auto before = plcs(kTwo);
    std::string text = kTwo;
    text.replace(text.find("R100: 7"), 7, "R100: 8");
    const auto after = plcs(text);
    EXPECT_EQ(before[0].fingerprint, after[0].fingerprint);
    EXPECT_NE(before[1].fingerprint, after[1].fingerprint);
}

TEST(ConfigFingerprint, AScalarQuotedIsNotTheSameAsPlain) {
    const auto plain = parse_config("profile: fbs\nmodel: FBs-24MC\n", "t.yaml");
    const auto quoted = parse_config("profile: fbs\nmodel: 'FBs-24MC'\n", "t.yaml");
    EXPECT_EQ(plain.model, quoted.model);
    EXPECT_NE(plain.fingerprint, quoted.fingerprint);
}

TEST(ConfigFingerprint, TheLogIsTheProcesssNotAPlcs) {
    const auto before = plcs(kTwo);
    const auto after = plcs("log: {level: debug}\n" + kTwo);
    EXPECT_EQ(before[0].fingerprint, after[0].fingerprint);
    EXPECT_EQ(before[1].fingerprint, after[1].fingerprint);
    EXPECT_EQ(parse_config("profile: fbs\n", "t.yaml").fingerprint,
              parse_config("profile: fbs\nlog: {level: warn}\n", "t.yaml").fingerprint);
}

TEST(ConfigFingerprint, TheSharedConsoleBelongsToTheEntriesWithoutTheirOwn) {
    const std::string own =
        "  - {name: c, profile: fbs, modbus: {tcp: {port: 5022}}, http: {port: 8081}}\n";
    const auto before = plcs("http: {port: 8080}\n" + kTwo + own);
    const auto after = plcs("http: {port: 8090}\n" + kTwo + own);
    EXPECT_NE(before[0].fingerprint, after[0].fingerprint);
    EXPECT_NE(before[1].fingerprint, after[1].fingerprint);
    EXPECT_EQ(before[2].fingerprint, after[2].fingerprint);
}

TEST(ConfigFingerprint, TheSamePlcElsewhereInTheListIsAnother) {
    // Its state file and its label go by its place: moved, it is a PLC the reload refuses.
    const auto one = plcs(
        "plcs:\n  - {profile: fbs, modbus: {tcp: {port: 5020}}}\n"
        "  - {profile: fbs, modbus: {tcp: {port: 5021}}}\n");
    const auto two = plcs(
        "plcs:\n  - {profile: fbs, modbus: {tcp: {port: 5021}}}\n"
        "  - {profile: fbs, modbus: {tcp: {port: 5020}}}\n");
    EXPECT_NE(one[0].fingerprint, two[1].fingerprint);
}

TEST(ConfigFingerprint, AProgramFilesLinesAreSummedToo) {
    const std::filesystem::path dir =
        std::filesystem::temp_directory_path() / ("fingerprint-" + std::to_string(::getpid()));
    std::filesystem::create_directories(dir);
    const std::string config = (dir / "c.yaml").string();
    const std::string text = "profile: fbs\nprogram: {file: p.il}\n";
    auto program = [&](const std::string& il) { std::ofstream(dir / "p.il") << il; };
    program("LD X0\nOUT Y0\n");
    const auto before = parse_config(text, config);
    program("LD X0\nOUT Y0\n");
    const auto same = parse_config(text, config);
    program("LD X1\nOUT Y0\n");
    const auto after = parse_config(text, config);
    std::filesystem::remove_all(dir);
    EXPECT_EQ(before.fingerprint, same.fingerprint);
    EXPECT_NE(before.fingerprint, after.fingerprint);
}

}  // namespace
}  // namespace plcemu::config
