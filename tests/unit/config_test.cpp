// Configuration (docs/configuration.md, Configuration): defaults, every key of the foundation, and
// errors naming file:line:col.

#include <gtest/gtest.h>

#include <cstdio>
#include <fstream>
#include <string>

#include "plcemu/config/config.hpp"
#include "plcemu/config/tree.hpp"
#include "plcemu/image/utf8.hpp"
#include "plcemu/daemon/plc.hpp"
#include "profiles/fbs/model.hpp"
#include "support/config_errors.hpp"

namespace plcemu::config {
namespace {

using testing::ConfigFailure;

ConfigFailure parse_error(const std::string& text) {
    return testing::config_failure([&] { parse_config(text, "t.yaml"); });
}

// Checks that `text` is refused at line:col with a message containing `needle`.
void expect_error(const std::string& text, int line, int col, const std::string& needle) {
    SCOPED_TRACE(text);
    testing::expect_config_error(parse_error(text), "t.yaml", line, col, needle);
}

// docs/configuration.md, Configuration / issue: every key but `profile` has a default, so
// `{profile: fbs}` alone is valid.
TEST(Config, ProfileAloneIsValidAndEverythingElseDefaults) {
    for (const char* text : {"{profile: fbs}", "profile: fbs\n", "# comment\nprofile: fbs # x\n"}) {
        SCOPED_TRACE(text);
        const Config c = parse_config(text, "t.yaml");
        EXPECT_EQ(c.path, "t.yaml");
        EXPECT_EQ(c.profile, "fbs");
        EXPECT_EQ(c.model, "FBs-24MC");
        EXPECT_EQ(c.station, 1);
        EXPECT_EQ(c.scan_ms, 10);
        EXPECT_DOUBLE_EQ(c.time_scale, 1.0);
        EXPECT_TRUE(c.modbus.tcp.enabled);
        EXPECT_EQ(c.modbus.tcp.bind, "0.0.0.0");  // as a real PLC: every interface, port 502
        EXPECT_EQ(c.modbus.tcp.port, 502);
        EXPECT_EQ(c.modbus.tcp.unknown_unit, UnknownUnit::Exception);
        EXPECT_TRUE(c.modbus.tcp.allow.empty());
        EXPECT_EQ(c.modbus.tcp.max_clients, 64);
        EXPECT_EQ(c.modbus.tcp.idle_timeout_s, 0);
        EXPECT_FALSE(c.modbus.rtu.has_value());
        EXPECT_FALSE(c.modbus.read_only);
        EXPECT_TRUE(c.modbus.write_protect.empty());
        EXPECT_TRUE(c.init.empty());
        EXPECT_TRUE(c.program.empty());
        EXPECT_TRUE(c.sections.empty());
        EXPECT_EQ(c.simulator.unit, 247);
        EXPECT_EQ(c.log.level, "info");
    }
}

TEST(Config, ReadsEveryFoundationKey) {
    const Config c = parse_config(
        "profile: fbs\n"
        "model: FBs-60MN\n"
        "station: 0x11\n"
        "scan_ms: 5\n"
        "time_scale: 60.5\n"
        "modbus:\n"
        "  tcp: {bind: 127.0.0.1, port: 5020, unknown_unit: silent}\n"
        "init:\n"
        "  R5000: [0xA556, 2, 10000, 20000, 0101h, -1]\n"
        "  D7: K42\n"
        "  M3: [1, 0, 1]\n"
        "  WM800: 0x03FF\n"
        "program:\n"
        "  - MOV: {en: M1926, s: WM800, d: R4012}\n"
        "  - MOV: {s: 7, d: D0}\n",
        "t.yaml");
    EXPECT_EQ(c.model, "FBs-60MN");
    EXPECT_EQ(c.station, 17);
    EXPECT_EQ(c.scan_ms, 5);
    EXPECT_DOUBLE_EQ(c.time_scale, 60.5);
    EXPECT_EQ(c.modbus.tcp.bind, "127.0.0.1");
    EXPECT_EQ(c.modbus.tcp.port, 5020);
    EXPECT_EQ(c.modbus.tcp.unknown_unit, UnknownUnit::Silent);
    ASSERT_EQ(c.init.size(), 4u);
    EXPECT_EQ(c.init[0].device, (image::Device{image::Area::R, 5000, false}));
    EXPECT_EQ(c.init[0].values,
              (std::vector<std::uint16_t>{0xA556, 2, 10000, 20000, 0x0101, 0xFFFF}));
    EXPECT_EQ(c.init[0].pos.line, 9);
    EXPECT_EQ(c.init[0].pos.column, 3);
    EXPECT_EQ(c.init[1].values, std::vector<std::uint16_t>{42});
    EXPECT_EQ(c.init[2].values, (std::vector<std::uint16_t>{1, 0, 1}));
    EXPECT_EQ(c.init[3].device, (image::Device{image::Area::M, 800, true}));
    ASSERT_EQ(c.program.size(), 2u);
    EXPECT_EQ(c.program[0].mnemonic, "MOV");
    EXPECT_EQ(c.program[0].pos.line, 14);
    EXPECT_EQ(c.program[0].pos.column, 5);
    ASSERT_EQ(c.program[0].operands.size(), 3u);
    EXPECT_EQ(c.program[0].operands[1].first, "s");
    EXPECT_EQ(c.program[0].operands[1].second.text, "WM800");
    EXPECT_EQ(c.program[0].operands[1].second.pos.line, 14);
    EXPECT_EQ(c.program[0].operands[1].second.pos.column, 25);
}

// R4167: low byte I/O points, high byte 0 MA / 1 MC / 2 MN.
// Each init device is checked against the PLC's areas at its key, every one, alongside the
// file's other errors (docs/configuration.md, "Configuration": each init: device on its own).
TEST(Config, EveryInitDeviceOutsideItsAreaIsAnErrorOfItsOwn) {
    const auto f = testing::config_failure([] {
        parse_config(
            "profile: fbs\n"
            "init: {R9000: 1, D5000: 1, D3999: [1, 2], R5: 3, WM2000: 1, CTR255: [1, 2, 3]}\n"
            "modbus: {write_protect: [Q1]}\n",
            "i.yaml");
    });
    // Counters are counted as counters: 256, whose values fill 312 words (it said 312).
    testing::expect_config_errors(
        f, "i.yaml",
        {{2, 8, "init: R9000 is outside this PLC's R area (8072 devices)"},
         {2, 18, "init: D5000 is outside this PLC's D area (4000 devices)"},
         {2, 28, "init: D3999-D4000 is outside this PLC's D area"},
         {2, 50, "init: M2000-M2015 is outside this PLC's M area"},
         {2, 61, "init: CTR255-CTR256 is outside this PLC's CTR area (256 devices)"},
         {3, 26, "modbus.write_protect entry: expected a device range"}});
}

TEST(Config, ModelCodes) {
    EXPECT_EQ(profiles::fbs::model_code("FBs-24MC"), 0x0118);
    EXPECT_EQ(profiles::fbs::model_code("FBs-10MA"), 0x000A);
    EXPECT_EQ(profiles::fbs::model_code("FBs-60MN"), 0x023C);
    EXPECT_EQ(profiles::fbs::model_code("FBs-32MC"), 0x0120);
    EXPECT_FALSE(profiles::fbs::model_code("FBs-25MC"));
    EXPECT_FALSE(profiles::fbs::model_code("FBs-24MX"));
    EXPECT_FALSE(profiles::fbs::model_code("FB-24MC"));
    EXPECT_FALSE(profiles::fbs::model_code("FBs-MC"));
    EXPECT_FALSE(profiles::fbs::model_code(""));
}

TEST(Config, ErrorsInTheRootNameTheirPosition) {
    expect_error("model: FBs-24MC\n", 1, 1, "'profile' is required");
    expect_error("profile: nope\n", 1, 10, "profile: expected one of fb, fbs, vb");
    expect_error("profile: fbx\n", 1, 10, "got 'fbx'");
    expect_error("profile: [fbs]\n", 1, 10, "profile: expected a scalar");
    expect_error("profile: fbs\nmodle: FBs-24MC\n", 2, 1, "unknown key 'modle' in config");
    expect_error("profile: fbs\nmodel: FBs-25MC\n", 2, 8, "model: expected an FBs model");
    expect_error("- profile: fbs\n", 1, 1, "must be a mapping");
    expect_error("just text\n", 1, 1, "must be a mapping");
}

TEST(Config, EmptyFileNamesLineOne) {
    expect_error("", 1, 1, "must be a mapping");
    expect_error("# only a comment\n", 1, 1, "must be a mapping");
}

TEST(Config, BadTypesAndRangesOfScalars) {
    expect_error("profile: fbs\nstation: abc\n", 2, 10, "station: expected an integer, got 'abc'");
    expect_error("profile: fbs\nstation: 0\n", 2, 10, "out of range 1..254");
    expect_error("profile: fbs\nstation: 255\n", 2, 10, "out of range 1..254");
    expect_error("profile: fbs\nstation: {a: 1}\n", 2, 10, "station: expected a scalar");
    expect_error("profile: fbs\nscan_ms: 0\n", 2, 10, "scan_ms: 0 is out of range 1..1000");
    expect_error("profile: fbs\nscan_ms: 1001\n", 2, 10, "out of range");
    expect_error("profile: fbs\nscan_ms: 2.5\n", 2, 10, "expected an integer");
    expect_error("profile: fbs\ntime_scale: fast\n", 2, 13, "time_scale: expected a number");
    expect_error("profile: fbs\ntime_scale: 0\n", 2, 13, "out of range");
    expect_error("profile: fbs\ntime_scale: 100001\n", 2, 13, "out of range");
    expect_error("profile: fbs\ntime_scale: .inf\n", 2, 13, "expected a number");
    // An integer beyond the grammar's 2^40 is out of range, as any other (it was "expected an
    // integer"), in whatever base it is written.
    expect_error("profile: fbs\nplant: {seed: 1099511627777}\n", 2, 15,
                 "plant.seed: 1099511627777 is out of range 0..1099511627776");
    expect_error("profile: fbs\nstation: 0x10000000000000000000\n", 2, 10,
                 "station: 0x10000000000000000000 is out of range 1..254");
    expect_error("profile: fbs\nstation: -99999999999999999999\n", 2, 10,
                 "station: -99999999999999999999 is out of range 1..254");
    expect_error("profile: fbs\nstation: 99999999999999999999x\n", 2, 10,
                 "station: expected an integer");
}

TEST(Config, ModbusSectionErrors) {
    expect_error("profile: fbs\nmodbus: 5\n", 2, 9, "modbus: expected a mapping");
    expect_error("profile: fbs\nmodbus:\n  tcp:\n    prot: 5020\n", 4, 5,
                 "unknown key 'prot' in modbus.tcp");
    expect_error("profile: fbs\nmodbus:\n  tcp:\n    port: 70000\n", 4, 11,
                 "modbus.tcp.port: 70000 is out of range 0..65535");
    expect_error("profile: fbs\nmodbus:\n  tcp:\n    port: [1]\n", 4, 11, "expected a scalar");
    expect_error("profile: fbs\nmodbus: {tcp: {bind: [a, b]}}\n", 2, 22,
                 "modbus.tcp.bind: expected a scalar");
    expect_error("profile: fbs\nmodbus: {tcp: {unknown_unit: maybe}}\n", 2, 30,
                 "expected 'exception' or 'silent'");
    expect_error("profile: fbs\nmodbus: {tcp: {enabled: perhaps}}\n", 2, 25,
                 "expected true or false");
    expect_error("profile: fbs\nmodbus: {udp: {}}\n", 2, 10, "unknown key 'udp' in modbus");
    expect_error("profile: fbs\nmodbus: {write_protect: [D5-D1]}\n", 2, 26,
                 "expected a device range");
}

TEST(Config, InitErrors) {
    expect_error("profile: fbs\ninit: [1, 2]\n", 2, 7, "init: expected a mapping");
    expect_error("profile: fbs\ninit:\n  Q5: 1\n", 3, 3,
                 "init key: 'Q5' is not a device of this PLC");
    expect_error("profile: fbs\ninit:\n  R0: [1, x]\n", 3, 11, "init.R0: expected an integer");
    expect_error("profile: fbs\ninit:\n  R0: 65536\n", 3, 7, "out of range -32768..65535");
    expect_error("profile: fbs\ninit:\n  R0: -32769\n", 3, 7, "out of range");
    expect_error("profile: fbs\ninit:\n  R0: [[1]]\n", 3, 8, "expected a scalar");
}

// docs/configuration.md, "Configuration": a key given twice is an error. In `init` and
// `plant.channels` that means the same device or channel, however it is spelled; the error points
// at the second key.
TEST(Config, InitNamingOneDeviceTwiceIsRefusedAtTheSecondKey) {
    expect_error("profile: fbs\ninit:\n  D7: 1\n  D7: 2\n", 4, 3,
                 "init: duplicate device 'D7' (first at line 3)");
    expect_error("profile: fbs\ninit:\n  D7: 1\n  R0: 5\n  D07: 2\n", 5, 3,
                 "init: duplicate device 'D07' (first at line 3 as 'D7')");
    expect_error("profile: fbs\ninit:\n  R0: [1, 2]\n  r0: 3\n", 4, 3,
                 "init: duplicate device 'r0' (first at line 3 as 'R0')");
    expect_error("profile: fbs\ninit: {WM800: 1, wm0800: 2}\n", 2, 18,
                 "duplicate device 'wm0800' (first at line 2 as 'WM800')");
    expect_error("profile: fbs\ninit: {TMR5: 1, tmr05: 2}\n", 2, 17, "duplicate device 'tmr05'");
    // Other devices are not duplicates, even where a run reaches them or a word holds them.
    const Config c = parse_config(
        "profile: fbs\ninit: {D7: [1, 2], D8: 3, M800: 1, WM800: 3, T5: 1, TMR5: 2}\n", "t.yaml");
    EXPECT_EQ(c.init.size(), 6u);
}

TEST(Config, PlantChannelNamedTwiceIsRefusedAtTheSecondKey) {
    expect_error("profile: fbs\nplant:\n  channels:\n    3: {k: 100}\n    3: {k: 200}\n", 5, 5,
                 "plant.channels: duplicate channel '3' (first at line 4)");
    expect_error("profile: fbs\nplant:\n  channels:\n    1: {}\n    2: {}\n    01: {}\n", 6, 5,
                 "plant.channels: duplicate channel '01' (first at line 4 as '1')");
    expect_error("profile: fbs\nplant: {channels: {0x1F: {}, 31: {}}}\n", 2, 30,
                 "duplicate channel '31' (first at line 2 as '0x1F')");
    const Config c =
        parse_config("profile: fbs\nplant: {channels: {0: {k: 1}, 1: {k: 2}}}\n", "t.yaml");
    ASSERT_EQ(c.plant.channels.size(), 2u);
    EXPECT_EQ(c.plant.channels[1].first, 1);
}

// An error quotes at most 40 characters of what the user wrote, escaped: a pasted megabyte does
// not flood the log, and a value cannot start a log line of its own.
TEST(Config, ExcerptCutsAndEscapes) {
    EXPECT_EQ(excerpt("R100"), "R100");
    EXPECT_EQ(excerpt(std::string(40, 'a')), std::string(40, 'a'));
    EXPECT_EQ(excerpt(std::string(41, 'a')), std::string(40, 'a') + "…");
    EXPECT_EQ(excerpt("abcdef", 3), "abc…");
    EXPECT_EQ(excerpt("a\nb\r\tc\x1b[31m\x7f"), "a\\nb\\r\\tc\\x1B[31m\\x7F");
    EXPECT_EQ(excerpt("a\xc2\x85"
                      "b\xe2\x80\xa8"
                      "c"),
              "a\\u0085b\\u2028c");  // NEL, LINE SEPARATOR
    // Characters, not bytes: a cut never splits a UTF-8 sequence; stray bytes are escaped.
    std::string e;
    for (int i = 0; i < 50; ++i) e += "é";
    std::string e40;
    for (int i = 0; i < 40; ++i) e40 += "é";
    EXPECT_EQ(excerpt(e), e40 + "…");
    EXPECT_EQ(excerpt("\xff\x80x"), "\\xFF\\x80x");
}

// A key or value cannot reorder the log line that quotes it: the bidirectional marks, embeddings,
// overrides and isolates are escaped like controls, and so is every byte that is not UTF-8.
TEST(Config, ExcerptEscapesBidiControlsAndBytesThatAreNotUtf8) {
    EXPECT_EQ(excerpt("a\u202Eb"), "a\\u202Eb");  // RIGHT-TO-LEFT OVERRIDE
    EXPECT_EQ(excerpt("\u200E\u200F\u202A\u202B\u202C\u202D\u2066\u2067\u2068\u2069\u061C"),
              "\\u200E\\u200F\\u202A\\u202B\\u202C\\u202D\\u2066\\u2067\\u2068\\u2069\\u061C");
    EXPECT_EQ(excerpt("\u2029\u009B"), "\\u2029\\u009B");  // PARAGRAPH SEPARATOR, CSI
    // Shown as nothing: a name quoted with one would look like another.
    EXPECT_EQ(excerpt("\uFEFFORG"), "\\uFEFFORG");  // BYTE ORDER MARK
    EXPECT_EQ(excerpt("R\u200B1\u200C\u200D\u2060"), "R\\u200B1\\u200C\\u200D\\u2060");
    // Every default-ignorable code point: soft hyphen, a variation selector, a Hangul filler,
    // an invisible operator, a tag character (beyond U+FFFF, as \U and eight digits).
    EXPECT_EQ(excerpt("X\u00AD\uFE0F\u3164\u2061\U000E00410"),
              "X\\u00AD\\uFE0F\\u3164\\u2061\\U000E00410");
    // Kept: letters of any script, and the characters next to the escaped ones.
    EXPECT_EQ(excerpt("\u00A0é€\u2027\u2030\u2070😀"), "\u00A0é€\u2027\u2030\u2070😀");
    // Not UTF-8: a lead byte without its continuation, overlong forms, a surrogate, beyond
    // U+10FFFF, and a sequence cut short by the end.
    EXPECT_EQ(excerpt("\xc3x"), "\\xC3x");
    EXPECT_EQ(excerpt("\xc0\xaf"), "\\xC0\\xAF");
    EXPECT_EQ(excerpt("\xe0\x80\xaf"), "\\xE0\\x80\\xAF");
    EXPECT_EQ(excerpt("\xed\xa0\x80"), "\\xED\\xA0\\x80");
    EXPECT_EQ(excerpt("\xf4\x90\x80\x80"), "\\xF4\\x90\\x80\\x80");
    EXPECT_EQ(excerpt("a\xe2\x80"), "a\\xE2\\x80");
    // An escaped character counts as one.
    EXPECT_EQ(excerpt("\u202E\u202Eab", 2), "\\u202E\\u202E…");
}

TEST(Config, Utf8CharDecodesWellFormedSequencesOnly) {
    using image::utf8_char;
    EXPECT_EQ(utf8_char("A").code, U'A');
    EXPECT_EQ(utf8_char("A").length, 1u);
    EXPECT_EQ(utf8_char("é").code, U'é');
    EXPECT_EQ(utf8_char("\u202E").code, U'\u202E');
    EXPECT_EQ(utf8_char("\u202E").length, 3u);
    EXPECT_EQ(utf8_char("😀").code, U'😀');
    EXPECT_EQ(utf8_char("😀").length, 4u);
    EXPECT_EQ(utf8_char("\xf4\x8f\xbf\xbf").code, char32_t{0x10FFFF});
    for (const char* bad : {"\x80", "\xc1\xbf", "\xe0\x9f\xbf", "\xed\xbf\xbf", "\xf0\x8f\xbf\xbf",
                            "\xf5\x80\x80\x80", "\xff", "\xe2\x28\xa1", "\xe2\x80"}) {
        EXPECT_EQ(utf8_char(bad).length, 0u) << excerpt(bad);
    }
}

TEST(Config, ErrorsNeverEchoAWholeHugeValue) {
    const std::string huge(1 << 20, 'x');
    const std::string long_key(1000, 'x');  // YAML keys stop at 1024 characters
    const std::string cut = "'" + std::string(40, 'x') + "…'";
    struct Case {
        std::string text;
        int line, col;
        std::string needle;
    };
    const Case cases[] = {
        {"profile: fbs\nstation: " + huge + "\n", 2, 10,
         "station: expected an integer, got " + cut},
        {"profile: " + huge + "\n", 1, 10, "got " + cut},
        {"profile: fbs\nmodel: " + huge + "\n", 2, 8, "got " + cut},
        {"profile: fbs\nmodbus: {tcp: {bind: " + huge + "}}\n", 2, 22, "got " + cut},
        {"profile: fbs\nlog: {" + long_key + ": 1}\n", 2, 7, "unknown key " + cut},
        {"profile: fbs\ninit: {R0: " + huge + "}\n", 2, 12, "init.R0: expected an integer"},
        {"profile: fbs\ninit: {R" + long_key + ": 1}\n", 2, 8, "is not a device of this PLC"},
        {"profile: fbs\nscan_ms: " + std::string(1 << 20, '0') + "5000\n", 2, 10,
         "scan_ms: " + std::string(40, '0') + "… is out of range"},
        {"profile: fbs\nprogram:\n  - " + long_key + ": 5\n", 3, 5 + 1000 + 2,
         std::string(40, 'x') + "…: expected a mapping"},
    };
    for (const Case& c : cases) {
        SCOPED_TRACE(c.text.substr(0, 60));
        const ConfigFailure f = parse_error(c.text);
        testing::expect_config_error(f, "t.yaml", c.line, c.col, c.needle);
        EXPECT_LT(f.what.size(), 300u) << f.what.substr(0, 400);
    }
}

// docs/configuration.md, "Configuration": a simulator unit that could never be reached is
// refused: 255 ("the device itself" over Modbus TCP, Modbus TCP implementation guide §4.4.1.2),
// or the PLC's own station. 0 (none) and any other unit stay valid.
TEST(Config, UnreachableSimulatorUnitsAreRefused) {
    expect_error("profile: fbs\nsimulator: {unit: 255}\n", 2, 19,
                 "simulator.unit: 255 is \"the device itself\"");
    expect_error("profile: fbs\nstation: 247\n", 2, 10,
                 "station: 247 is also this PLC's simulator unit");
    expect_error("profile: fbs\nstation: 9\nsimulator: {unit: 9}\n", 3, 19,
                 "simulator.unit: 9 is also this PLC's station");
    expect_error("profile: fbs\nsimulator: {unit: 1}\n", 2, 19,
                 "simulator.unit: 1 is also this PLC's station");
    EXPECT_EQ(
        parse_config("profile: fbs\nstation: 247\nsimulator: {unit: 0}\n", "t.yaml").simulator.unit,
        0);
    EXPECT_EQ(parse_config("profile: fbs\nsimulator: {unit: 254}\n", "t.yaml").simulator.unit, 254);
}

TEST(Config, ErrorsEscapeControlCharactersOfAValue) {
    for (const char* text :
         {"profile: fbs\nmodel: \"FBs\\nplcemud: fake line\"\n",
          "profile: fbs\nmodel: \"FBs\\rplcemud: \\e[2Kfake\"\n",
          "profile: fbs\nmodel: \"FBs\\Lfake\\Nline\"\n", "profile: fbs\n\"x\\ny\": 1\n"}) {
        SCOPED_TRACE(text);
        const ConfigFailure f = parse_error(text);
        ASSERT_TRUE(f.thrown);
        EXPECT_EQ(f.what.find_first_of("\n\r\x1b"), std::string::npos) << f.what;
        EXPECT_EQ(f.what.find("\xe2\x80\xa8"), std::string::npos) << f.what;
        EXPECT_EQ(f.what.find("\xc2\x85"), std::string::npos) << f.what;
    }
    expect_error("profile: fbs\nmodel: \"FBs\\nplcemud: fake\"\n", 2, 8,
                 "got 'FBs\\nplcemud: fake'");
}

TEST(Config, ProgramErrors) {
    expect_error("profile: fbs\nprogram: 5\n", 2, 10, "program: expected a list");
    expect_error("profile: fbs\nprogram:\n  - MOV\n", 3, 5, "expected one instruction");
    expect_error("profile: fbs\nprogram:\n  - {MOV: {}, TPCTL: {}}\n", 3, 5,
                 "expected one instruction");
    expect_error("profile: fbs\nprogram:\n  - MOV: 5\n", 3, 10, "MOV: expected a mapping");
    expect_error("profile: fbs\nprogram:\n  - MOV: {s: [R1]}\n", 3, 14, "MOV.s: expected a scalar");
}

TEST(Config, YamlSyntaxErrorsNameTheirPosition) {
    const ConfigFailure f = parse_error("profile: fbs\nmodbus: {tcp: {port: 1}\n");
    ASSERT_TRUE(f.thrown);
    EXPECT_EQ(f.pos.file.str(), "t.yaml");
    EXPECT_GE(f.pos.line, 2) << f.what;
    EXPECT_GE(f.pos.column, 1) << f.what;
    expect_error("profile: fbs\n  station: 1\n", 2, 10, "");
    expect_error("profile: fbs\nstation: 1\nstation: 2\n", 3, 1, "duplicate key 'station'");
    // The first refused key is the one named, whether it repeats a key or is unknown.
    expect_error("profile: fbs\nstation: 1\nstation: 2\nbogus: 1\n", 3, 1,
                 "duplicate key 'station'");
    expect_error("profile: fbs\nbogus: 1\nstation: 1\nstation: 2\n", 2, 1,
                 "unknown key 'bogus' in config (expected one of: profile, model, station,");
    expect_error("profile: fbs\nbogus: 1\nbogus: 2\n", 2, 1, "unknown key 'bogus'");
    expect_error("profile: fbs\nmodbus: {tcp: {port: 1, port: 2}}\n", 2, 25,
                 "duplicate key 'port' in modbus.tcp");
    expect_error("profile: fbs\nprogram:\n  - MOV: {s: R1, d: R2, s: R3}\n", 3, 25,
                 "MOV: duplicate operand 's'");
}

// A tab in the indentation made the YAML reader say "illegal map value" or "end of map not
// found" without naming the tab: a tab that indents the error's line or the one before is said.
TEST(Config, ATabInTheIndentationIsNamedBesideTheReadersWords) {
    expect_error("profile: fbs\nmodbus:\n\ttcp:\n\t\tport: 502\n", 3, 5,
                 "illegal map value (line 3 is indented with a tab at column 1: YAML indents "
                 "with spaces only)");
    expect_error("profile: fbs\nmodbus:\n  tcp:\n  \tport: 43000\n", 4, 8,
                 "(line 4 is indented with a tab at column 3");
    // A tab after a key or inside a flow list is no indentation.
    expect_error("profile: fbs\nx: [1,\n\t2]\nname:\tx\n", 2, 1, "unknown key 'x'");
    // A legal tab (a block scalar's line) well before the error is not blamed.
    const ConfigFailure f =
        parse_error("profile: fbs\nx: |\n  \tcontent\n\nmodbus: {tcp: {port: 1}\n");
    ASSERT_TRUE(f.thrown);
    EXPECT_EQ(f.what.find("tab"), std::string::npos) << f.what;
}

// An RTU frame is binary: a Modbus RTU line has 8 data bits (FATEK's serial line may have 7).
TEST(Config, ModbusRtuTakesEightDataBits) {
    expect_error("profile: fbs\nmodbus: {rtu: {device: /dev/ttyS1, data_bits: 7}}\n", 2, 47,
                 "modbus.rtu.data_bits: Modbus RTU carries 8-bit bytes: expected 8");
    EXPECT_EQ(
        parse_config("profile: fbs\nmodbus: {rtu: {device: /dev/ttyS1, data_bits: 8}}\n", "t.yaml")
            .modbus.rtu->data_bits,
        8);
}

// A PLC's serial line may say it echoes what is sent (docs/configuration.md); off by default.
TEST(Config, APlcsSerialLineMaySayItEchoes) {
    EXPECT_FALSE(parse_config("profile: fbs\nmodbus: {rtu: {device: /dev/ttyS1}}\n", "t.yaml")
                     .modbus.rtu->echo);
    EXPECT_TRUE(
        parse_config("profile: fbs\nmodbus: {rtu: {device: /dev/ttyS1, echo: true}}\n", "t.yaml")
            .modbus.rtu->echo);
    expect_error("profile: fbs\nmodbus: {rtu: {device: /dev/ttyS1, echo: 2}}\n", 2, 42,
                 "modbus.rtu.echo");
}

// A config is one YAML document: a second one is refused where it begins, not dropped unread.
TEST(Config, ASecondDocumentIsRefusedWhereItBegins) {
    expect_error("profile: fbs\nstation: 1\n---\nprofile: vb\nbogus_key: 1\n", 3, 1,
                 "a second YAML document: a config file is one document");
    expect_error("profile: fbs\n...\nstation: 2\n", 3, 1, "a second YAML document");
    // No value takes a NUL: a path would be cut at it (`evil.state\0.x` opened `evil.state`).
    expect_error("profile: fbs\npersistence: {file: \"evil.state\\0.x\"}\n", 2, 21,
                 "a NUL character (\\0) in a value");
    // A document marked at its start, or ended by `...`, is one document.
    EXPECT_EQ(parse_config("---\nprofile: fbs\nstation: 3\n...\n", "t.yaml").station, 3);
}

// persistence.retentive holds at most 256 ranges (the state file keeps them and R4057 beside);
// persistence.file's name leaves room for the names the daemon makes after it.
TEST(Config, RetentiveRangesAndTheStateFilesNameHaveTheirLimits) {
    std::string ranges;
    for (int i = 0; i < 257; ++i) ranges += (i == 0 ? "D" : ", D") + std::to_string(i);
    expect_error("profile: fbs\npersistence:\n  retentive: [" + ranges + "]\n", 3, 14,
                 "persistence.retentive: at most 256 ranges");
    ranges = ranges.substr(0, ranges.rfind(','));
    EXPECT_EQ(parse_config("profile: fbs\npersistence:\n  retentive: [" + ranges + "]\n", "t.yaml")
                  .persistence.retentive->size(),
              256u);
    expect_error("profile: fbs\npersistence: {file: /var/lib/" + std::string(231, 'x') + "}\n", 2,
                 21, "the state file's name (after the last '/') is 231 bytes long; at most 230");
    // A default name is the config's: a long one is refused too (its place: the root).
    const std::string stem(225, 'c');
    testing::expect_config_error(
        testing::config_failure([&] { parse_config("profile: fbs\n", stem + ".yaml"); }),
        stem + ".yaml", 1, 1, "is 231 bytes long; at most 230");
    // An entry's: the stem, a dash and its name (here at the entry's line).
    testing::expect_config_error(testing::config_failure([&] {
                                     parse_plcs("plcs:\n  - {name: line-a, profile: fbs}\n",
                                                std::string(220, 'c') + ".yaml");
                                 }),
                                 std::string(220, 'c') + ".yaml", 2, 5,
                                 "plcs[0] (line-a): persistence.file: the state file's name");
    EXPECT_NO_THROW(parse_config(
        "profile: fbs\npersistence: {file: " + std::string(230, 'x') + "}\n", "t.yaml"));
}

// Nesting past 64 levels is refused at the first node past them, while the YAML is parsed
// (docs/configuration.md, "The config file"): not the YAML library's own recursion error.
TEST(Config, DeepNestingIsRefusedAtTheFirstLevelPastTheLimit) {
    const std::string flow =
        "profile: fbs\nprogram: " + std::string(100'000, '[') + std::string(100'000, ']') + "\n";
    expect_error(flow, 2, 74, "the config nests too deeply or repeats too much (more than 64");
    std::string block;
    for (int i = 0; i < 3000; ++i) block += std::string(static_cast<std::size_t>(i), ' ') + "k:\n";
    expect_error(block, 65, 65, "the config nests too deeply");
    // 64 levels are taken.
    expect_error("profile: fbs\nx: " + std::string(63, '[') + std::string(63, ']') + "\n", 2, 1,
                 "unknown key 'x'");
}

// A tree read without YAML (config/tree.hpp) goes through the same loader: values, the path, and
// errors at the positions the tree's nodes carry.
TEST(Config, ReadConfigTakesATreeAsParseConfigTakesText) {
    auto scalar = [](const std::string& text, int line, int column) {
        Node n;
        n.kind = Node::Kind::Scalar;
        n.text = text;
        n.pos = {"t.tree", line, column};
        return n;
    };
    Node root;
    root.kind = Node::Kind::Map;
    root.pos = {"t.tree", 1, 1};
    root.entries.push_back({scalar("profile", 1, 2), scalar("fbs", 1, 11)});
    root.entries.push_back({scalar("station", 2, 2), scalar("7", 2, 11)});
    const Config c = read_config(root, "t.tree");
    EXPECT_EQ(c.profile, "fbs");
    EXPECT_EQ(c.station, 7);
    EXPECT_EQ(c.path, "t.tree");

    root.entries.push_back({scalar("statoin", 3, 4), scalar("1", 3, 13)});
    const ConfigFailure f = testing::config_failure([&] { read_config(root, "t.tree"); });
    testing::expect_config_error(f, "t.tree", 3, 4, "unknown key 'statoin' in config");
}

TEST(Config, LogLevel) {
    EXPECT_EQ(parse_config("profile: fbs\nlog: {level: debug}\n", "t.yaml").log.level, "debug");
    expect_error("profile: fbs\nlog: {level: loud}\n", 2, 14, "log.level: expected trace");
}

// load_config reads a file and names it in errors; a missing file is a config error too.
TEST(Config, LoadConfigNamesTheFile) {
    const std::string path = ::testing::TempDir() + "plcemu_config_test.yaml";
    {
        std::ofstream out(path);
        out << "profile: fbs\nstation: 300\n";
    }
    try {
        load_config(path);
        ADD_FAILURE() << "accepted";
    } catch (const ConfigError& e) {
        EXPECT_EQ(std::string(e.what()).rfind(path + ":2:10: ", 0), 0u) << e.what();
    }
    std::remove(path.c_str());
    try {
        load_config(path);
        ADD_FAILURE() << "accepted a missing file";
    } catch (const ConfigError& e) {
        EXPECT_EQ(std::string(e.what()).rfind(path + ": ", 0), 0u) << e.what();
        EXPECT_NE(std::string(e.what()).find("cannot open"), std::string::npos) << e.what();
    }
}

// The files under config/ are valid (default.yaml once TPCTL is there: see the system tests).
TEST(Config, ExampleYamlIsValidAndHoldsTheDefaults) {
    const Config c = load_config(std::string(PLCEMU_SOURCE_DIR) + "/config/example.yaml");
    const Config d = parse_config("profile: fbs", "d");
    EXPECT_EQ(c.model, d.model);
    EXPECT_EQ(c.station, d.station);
    EXPECT_EQ(c.scan_ms, d.scan_ms);
    EXPECT_DOUBLE_EQ(c.time_scale, d.time_scale);
    EXPECT_EQ(c.modbus.tcp.bind, d.modbus.tcp.bind);
    EXPECT_EQ(c.modbus.tcp.port, d.modbus.tcp.port);
    EXPECT_EQ(c.modbus.tcp.max_clients, d.modbus.tcp.max_clients);
    EXPECT_EQ(c.modbus.tcp.idle_timeout_s, d.modbus.tcp.idle_timeout_s);
    EXPECT_EQ(c.modbus.tcp.unknown_unit, d.modbus.tcp.unknown_unit);
    EXPECT_EQ(c.simulator.unit, d.simulator.unit);
    EXPECT_EQ(c.log.level, d.log.level);
    EXPECT_TRUE(c.init.empty());
    EXPECT_TRUE(c.program.empty());
}

// Errors only the PLC build finds (init beyond an area) still name file:line:col.
TEST(Config, InitOutsideAnAreaIsRefusedAtItsKey) {
    // Refused as the file is read (--check-config too), not when the PLC is built.
    testing::expect_config_error(
        testing::config_failure(
            [] { parse_config("profile: fbs\ninit:\n  R8070: [1, 2, 3]\n", "t.yaml"); }),
        "t.yaml", 3, 3, "init: R8070-R8072 is outside this PLC's R area");
    const Config ok = parse_config("profile: fbs\ninit:\n  R8069: [1, 2, 3]\n  M2001: 1\n", "t");
    daemon::Plc plc(ok);
    EXPECT_EQ(plc.image().word(image::Area::R, 8071), 3);
    EXPECT_TRUE(plc.image().bit(image::Area::M, 2001));
}

// Presets are applied after the power-up defaults, so a preset of R4012 wins.
TEST(Config, InitWinsOverPowerUpDefaults) {
    const Config c = parse_config("profile: fbs\ninit: {R4012: 0x00FF, R4005: 0x0303}\n", "t");
    daemon::Plc plc(c);
    EXPECT_EQ(plc.image().word(image::Area::R, 4012), 0x00FF);
    EXPECT_EQ(plc.image().word(image::Area::R, 4013), 0xFFFF);
    EXPECT_EQ(plc.image().word(image::Area::R, 4005), 0x0303);
}

}  // namespace
}  // namespace plcemu::config
