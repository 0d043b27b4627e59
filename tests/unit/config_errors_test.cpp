// Configuration errors reported together (docs/configuration.md, "Configuration"): every error a
// file has, up to config::Errors::kMax, each at its file:line:col and in the order of the file;
// a YAML syntax error, or one that leaves nothing to read on, stops the loader where it stands;
// checks that compare several keys (or several PLCs) run only when those keys read cleanly.

#include <gtest/gtest.h>

#include <string>
#include <tuple>

#include "daemon/daemon.hpp"
#include "plcemu/config/config.hpp"
#include "plcemu/config/reader.hpp"
#include "support/config_errors.hpp"

namespace plcemu::config {
namespace {

using testing::ConfigFailure;
using testing::expect_config_errors;

ConfigFailure one_plc(const std::string& text) {
    return testing::config_failure([&] { parse_config(text, "t.yaml"); });
}

ConfigFailure plcs(const std::string& text) {
    return testing::config_failure([&] { parse_plcs(text, "t.yaml"); });
}

// Three keys in error, written in another order than the loader reads them (station, scan_ms,
// modbus): three errors, in the order of the file.
TEST(ConfigErrors, ThreeErrorsInThreeKeysAreReportedInTheOrderOfTheFile) {
    const std::string text =
        "profile: fbs\n"
        "modbus:\n"
        "  tcp:\n"
        "    port: 70000\n"
        "scan_ms: fast\n"
        "station: 300\n";
    const ConfigFailure f = one_plc(text);
    expect_config_errors(f, "t.yaml",
                         {{4, 11, "modbus.tcp.port: 70000 is out of range 0..65535"},
                          {5, 10, "scan_ms: expected an integer, got 'fast'"},
                          {6, 10, "station: 300 is out of range"}});
    // Each alone is refused with the message it has among the others.
    for (std::size_t i = 0; i < f.all.size(); ++i) {
        EXPECT_EQ(f.lines[i], "t.yaml:" + std::to_string(f.all[i].pos.line) + ":" +
                                  std::to_string(f.all[i].pos.column) + ": " + f.all[i].message);
    }
    const ConfigFailure alone = one_plc("profile: fbs\nscan_ms: fast\n");
    EXPECT_EQ(alone.what, "t.yaml:2:10: scan_ms: expected an integer, got 'fast'");
    EXPECT_EQ(alone.lines, std::vector<std::string>{alone.what});
}

// A program entry in error is skipped and the next ones are still read; a listener's keys are
// each read on their own.
TEST(ConfigErrors, BadProgramEntriesAndBadListenerKeysAreAllReported) {
    const std::string text =
        "profile: fbs\n"
        "program:\n"
        "  - MOV: {en: M0, s: K5, d: D0}\n"
        "  - MOV\n"
        "  - MOV: {s: R1, d: R2}\n"
        "  - MOV: [R1, R2]\n"
        "modbus:\n"
        "  tcp:\n"
        "    bind: localhost\n"
        "    prot: 1\n"
        "    max_clients: 0\n";
    expect_config_errors(one_plc(text), "t.yaml",
                         {{4, 5, "program entry: expected one instruction with its operands"},
                          {6, 10, "MOV: expected a mapping of operands"},
                          {9, 11, "modbus.tcp.bind: expected a numeric IPv4 or IPv6 address"},
                          {10, 5, "unknown key 'prot' in modbus.tcp"},
                          {11, 18, "modbus.tcp.max_clients: 0 is out of range 1..10000"}});
}

// Past Errors::kMax the loader stops, as a compiler does: the first kMax errors, then a line
// saying it stopped.
TEST(ConfigErrors, FiftyErrorsShowTheFirstTwentyAndSayTheLoaderStopped) {
    std::string text = "profile: fbs\n";
    for (int i = 0; i < 50; ++i) text += "key" + std::to_string(i) + ": 1\n";
    const ConfigFailure f = one_plc(text);
    ASSERT_TRUE(f.thrown);
    EXPECT_TRUE(f.stopped);
    ASSERT_EQ(f.all.size(), Errors::kMax);
    ASSERT_EQ(Errors::kMax, 20u);
    ASSERT_EQ(f.lines.size(), 21u);
    for (int i = 0; i < 20; ++i) {
        EXPECT_EQ(f.lines[static_cast<std::size_t>(i)].rfind("t.yaml:" + std::to_string(i + 2) +
                                                                 ":1: unknown key 'key" +
                                                                 std::to_string(i) + "' in config",
                                                             0),
                  0u)
            << f.lines[static_cast<std::size_t>(i)];
    }
    EXPECT_EQ(f.lines.back(), "t.yaml: too many errors, stopped after the 20 above");
    EXPECT_EQ(f.what, f.lines.front());
}

// Exactly kMax errors: all of them, and no line saying the loader stopped.
TEST(ConfigErrors, TwentyErrorsAreAllShownWithoutStopping) {
    std::string text = "profile: fbs\n";
    for (int i = 0; i < 20; ++i) text += "key" + std::to_string(i) + ": 1\n";
    const ConfigFailure f = one_plc(text);
    ASSERT_TRUE(f.thrown);
    EXPECT_FALSE(f.stopped);
    EXPECT_EQ(f.all.size(), 20u);
    EXPECT_EQ(f.lines.size(), 20u);
}

// A YAML syntax error leaves no tree to read on: it is the only error, whatever else is wrong.
TEST(ConfigErrors, AYamlSyntaxErrorIsReportedAlone) {
    const ConfigFailure f = one_plc("profile: fbs\nscan_ms: fast\nstation: [1, 2\nfoo: 1\n");
    ASSERT_TRUE(f.thrown);
    ASSERT_EQ(f.all.size(), 1u);
    EXPECT_EQ(f.lines, std::vector<std::string>{f.what});
    EXPECT_GE(f.pos.line, 3);
    EXPECT_EQ(f.what.find("scan_ms"), std::string::npos) << f.what;
}

// Without a profile nothing below it can be read (devices are spelt the profile's way): the
// unknown keys before it are reported, then the loader stops there.
TEST(ConfigErrors, AMissingProfileStopsAfterTheKeysAlreadyRefused) {
    expect_config_errors(one_plc("station: 300\nprot: 1\n"), "t.yaml",
                         {{1, 1, "'profile' is required"}, {2, 1, "unknown key 'prot' in config"}});
}

// A key in error keeps its default, and the checks that compare keys do not run: a station that
// is out of range is not also "the simulator's unit" at its default.
TEST(ConfigErrors, AKeyInErrorCausesNoFollowOnErrors) {
    expect_config_errors(one_plc("profile: fbs\nstation: 300\nsimulator: {unit: 1}\n"), "t.yaml",
                         {{2, 10, "station: 300 is out of range"}});
    // The same list entry is not refused twice (it is no range, let alone one on this PLC).
    expect_config_errors(one_plc("profile: fbs\nmodbus: {write_protect: [D1-, D9000-D9001]}\n"),
                         "t.yaml",
                         {{2, 26, "modbus.write_protect entry: expected a device range"},
                          {2, 31, "modbus.write_protect entry: D9000-D9001"}});
}

// `plcs:`: the errors of every entry, each named by its entry, in the order of the file.
TEST(ConfigErrors, ErrorsInTwoPlcsEntriesAreAllReportedEachNamingItsEntry) {
    const std::string text =
        "plcs:\n"
        "  - name: kiln\n"
        "    profile: fbs\n"
        "    station: 300\n"
        "    modbus: {tcp: {port: 1502}}\n"
        "  - profile: vb\n"
        "    scan_ms: 0\n"
        "    modbus: {tcp: {port: 1503, prot: 1}}\n"
        "  - profile: fbs\n"
        "    modbus: {tcp: {port: 1504}}\n";
    expect_config_errors(plcs(text), "t.yaml",
                         {{4, 14, "plcs[0] (kiln): station: 300 is out of range"},
                          {7, 14, "plcs[1]: scan_ms: 0 is out of range 1..1000"},
                          {8, 32, "plcs[1]: unknown key 'prot' in modbus.tcp"}});
}

// An entry in error is not compared with the others: its station at the default would only
// clash with the first entry's on their shared listener.
TEST(ConfigErrors, APlcsEntryInErrorIsNotComparedWithTheOthers) {
    const std::string text =
        "plcs:\n"
        "  - profile: fbs\n"
        "    modbus: {tcp: {port: 1502}}\n"
        "  - profile: fbs\n"
        "    station: many\n"
        "    modbus: {tcp: {port: 1502}}\n";
    expect_config_errors(plcs(text), "t.yaml",
                         {{5, 14, "plcs[1]: station: expected an integer, got 'many'"}});
    // Keys beside `plcs:` are refused once each, as belonging to one PLC or as unknown.
    expect_config_errors(
        plcs("station: 2\nplcs:\n  - profile: fbs\nfoo: 1\n"), "t.yaml",
        {{1, 1, "station: belongs to one PLC"},
         {4, 1, "unknown key 'foo' in config (expected one of: plcs, log, http)"}});
}

// The programs of several PLCs are bound one after the other, and the errors of each reported.
TEST(ConfigErrors, ProgramOperandErrorsOfSeveralPlcsAreAllReported) {
    const std::string text =
        "plcs:\n"
        "  - profile: fbs\n"
        "    modbus: {tcp: {port: 1502}}\n"
        "    program:\n"
        "      - MOV: {s: R1, d: Q7}\n"
        "  - profile: fbs\n"
        "    modbus: {tcp: {port: 1503}}\n"
        "    program:\n"
        "      - MOV: {s: Q8, d: R1}\n";
    const std::vector<Config> configs = parse_plcs(text, "t.yaml");
    const ConfigFailure f = testing::config_failure([&] { daemon::probe_all(configs); });
    expect_config_errors(f, "t.yaml", {{5, 25, "plcs[0]: MOV.d"}, {9, 18, "plcs[1]: MOV.s"}});
}

// A profile's own section is read like the common ones: each key and each list entry on its
// own, so the four errors in this FBs `temperature:` are all reported.
TEST(ConfigErrors, EveryErrorInTheFbsTemperatureSectionIsReported) {
    const ConfigFailure f = one_plc(
        "profile: fbs\n"
        "temperature:\n"
        "  table: X0\n"
        "  modules: [TC6:K, TC7, RTD6:K]\n"
        "  scan_rate: slow\n");
    expect_config_errors(f, "t.yaml",
                         {{3, 10, "temperature.table: expected an R or D register"},
                          {4, 20, "temperature.modules: unknown module 'TC7'"},
                          {4, 25, "temperature.modules: unknown sensor 'K'"},
                          {5, 14, "temperature.scan_rate: expected 'normal' or 'fast'"}});
}

// A table the PLC's registers cannot hold (its four words and one per module) is refused at its
// key: at R8071, or across R4168-R4999, it would never be valid. D3995 leaves room for one
// module, R8064 not for five.
TEST(ConfigErrors, ATemperatureTablePastThePlcsRegistersIsRefused) {
    for (const auto& [table, modules, words] :
         {std::tuple{"R8071", "[]", "R8071-R8075 (5 words"},
          std::tuple{"R4165", "[TC6:K]", "R4165-R4169 (5 words"},
          std::tuple{"R8064", "[TC6, TC6, TC6, TC6, TC6]", "R8064-R8072 (9 words"}}) {
        const ConfigFailure f = one_plc(std::string("profile: fbs\ntemperature:\n  table: ") +
                                        table + "\n  modules: " + modules + "\n");
        expect_config_errors(f, "t.yaml",
                             {{3, 10,
                               std::string("temperature.table: ") + words +
                                   ": SR+0 to SR+3 and one per module) are not all "
                                   "registers of this PLC"}});
    }
    EXPECT_NO_THROW(parse_config("profile: fbs\ntemperature: {table: D3995}\n", "t.yaml"));
}

// The FB's `temperature:`: keys of the FBs and module entries, each its own error.
TEST(ConfigErrors, EveryErrorInTheFbTemperatureSectionIsReported) {
    const ConfigFailure f = one_plc(
        "profile: fb\n"
        "temperature:\n"
        "  scan_rate: fast\n"
        "  modules: [FB-2AK4, FB-2AX4, FB-4AK24]\n");
    expect_config_errors(
        f, "t.yaml",
        {{3, 14, "temperature.scan_rate is not valid in profile fb"},
         {4, 22, "temperature.modules: unknown module 'FB-2AX4'"},
         {4, 31,
          "temperature.modules: FB-4AK24 cannot be used together with the FB-2AK4 at "
          "t.yaml:4:13"}});
}

// The VB's three sections: an error in `modules:`, in `mbus:` and in `file_registers:`, and
// two in one `modules:` list.
TEST(ConfigErrors, EveryErrorInTheVbSectionsIsReported) {
    const ConfigFailure f = one_plc(
        "profile: vb\n"
        "modules: [VB-8T, VB-9T, {type: VB-4PT, mode: -1}]\n"
        "mbus:\n"
        "  transport: udp\n"
        "  tcp: {host: plc.local}\n"
        "  routes: {0: \"127.0.0.1:5022\"}\n"
        "file_registers: M0-M9\n");
    expect_config_errors(f, "t.yaml",
                         {{2, 18, "modules.type: unknown module 'VB-9T'"},
                          {2, 46, "modules.mode: -1 is out of range"},
                          {4, 14, "mbus.transport: expected tcp or rtu, got 'udp'"},
                          {5, 15, "mbus.tcp.host: expected an IP address"},
                          {6, 12, "mbus.routes station: 0 is out of range"},
                          {7, 17, "file_registers: expected a range of D0-D7999"}});
}

// A reader without an error list (a profile's own sections) stops at the first error as before.
TEST(ConfigErrors, AReaderWithoutAnErrorListThrowsTheFirstError) {
    Node n;
    n.kind = Node::Kind::Map;
    for (const char* k : {"a", "b"}) {
        Node key;
        key.kind = Node::Kind::Scalar;
        key.text = k;
        key.pos = {"t.yaml", k[0] == 'a' ? 1 : 2, 1};
        n.entries.push_back({key, Node{}});
    }
    const ConfigFailure f = testing::config_failure([&] { Reader().check_keys(n, "x", {"c"}); });
    testing::expect_config_error(f, "t.yaml", 1, 1, "unknown key 'a' in x");
    EXPECT_EQ(f.all.size(), 1u);
}

}  // namespace
}  // namespace plcemu::config
