// MOV (docs/configuration.md, Configuration): word move while EN is ON; WMn is 16 bits from Mn; EN
// a bit device or a constant; operand errors name file:line:col.

#include <gtest/gtest.h>

#include <string>

#include "plcemu/daemon/plc.hpp"
#include "support/profiles.hpp"
#include "plcemu/config/config.hpp"
#include "plcemu/engine/engine.hpp"
#include "plcemu/image/image.hpp"
#include "plcemu/instructions/instructions.hpp"
#include "support/config_errors.hpp"

namespace plcemu::instructions {
namespace {

using image::Area;

// A PLC running `program` (YAML list entries, one per line). Kept here: a bare engine over
// the image (no plant, no map), the program on its own.
struct Rig {
    explicit Rig(const std::string& program)
        : config(config::parse_config("profile: fbs\nprogram:\n" + program, "p.yaml")),
          engine(img, {}, daemon::build_program(config), testing::fbs().specials(config)) {
        engine.power_up();
    }
    void scan(int n = 1) { engine.run_scans(static_cast<std::uint64_t>(n)); }

    image::Image img{testing::fbs_layout()};
    config::Config config;
    engine::Engine engine;
};

// The program text starts at line 3 ("profile: fbs", "program:").
void expect_error(const std::string& program, int line, int col, const std::string& needle) {
    SCOPED_TRACE(program);
    testing::expect_config_error(testing::config_failure([&] { Rig rig(program); }), "p.yaml", line,
                                 col, needle);
}

// MOV: {en: M1926, s: WM800, d: R4012}, as in the manual's FUN86 example (FBs manual §21.7;
// docs/profile-fbs.md, FUN86 TPCTL).
TEST(Mov, ManualExampleMovesWm800ToR4012) {
    Rig rig("  - MOV: {en: M1926, s: WM800, d: R4012}\n");
    rig.img.write_word({Area::M, 800, true}, 0x0305);
    rig.scan();
    EXPECT_EQ(rig.img.word(Area::R, 4012), 0x0305);  // M800, M802, M808, M809
    rig.img.set_bit(Area::M, 815, true);
    rig.scan();
    EXPECT_EQ(rig.img.word(Area::R, 4012), 0x8305);
}

TEST(Mov, MovesWordsEveryScanWhileEnabled) {
    Rig rig("  - MOV: {en: M0, s: R100, d: D7}\n");
    rig.img.set_word(Area::R, 100, 1234);
    rig.scan();
    EXPECT_EQ(rig.img.word(Area::D, 7), 0);  // M0 OFF
    rig.img.set_bit(Area::M, 0, true);
    rig.scan();
    EXPECT_EQ(rig.img.word(Area::D, 7), 1234);
    rig.img.set_word(Area::R, 100, 99);
    rig.scan();
    EXPECT_EQ(rig.img.word(Area::D, 7), 99);
    rig.img.set_bit(Area::M, 0, false);
    rig.img.set_word(Area::R, 100, 5);
    rig.scan();
    EXPECT_EQ(rig.img.word(Area::D, 7), 99);  // D keeps its value when EN goes OFF
}

// docs/configuration.md, Configuration: an enable operand may be any bit device or a constant
// (absent = always).
TEST(Mov, EnableIsAnyBitDeviceOrAConstant) {
    Rig rig(
        "  - MOV: {s: 1, d: R1}\n"
        "  - MOV: {en: 1, s: 2, d: R2}\n"
        "  - MOV: {en: 0, s: 3, d: R3}\n"
        "  - MOV: {en: X5, s: 4, d: R4}\n"
        "  - MOV: {en: Y6, s: 5, d: R5}\n"
        "  - MOV: {en: S7, s: 6, d: R6}\n"
        "  - MOV: {en: T8, s: 7, d: R7}\n"
        "  - MOV: {en: C9, s: 8, d: R8}\n"
        "  - MOV: {en: M1924, s: 9, d: R9}\n");
    rig.scan();
    EXPECT_EQ(rig.img.word(Area::R, 1), 1);
    EXPECT_EQ(rig.img.word(Area::R, 2), 2);
    EXPECT_EQ(rig.img.word(Area::R, 3), 0);
    for (std::uint32_t i = 4; i <= 8; ++i) EXPECT_EQ(rig.img.word(Area::R, i), 0) << i;
    EXPECT_EQ(rig.img.word(Area::R, 9), 9);  // first scan pulse
    rig.img.set_bit(Area::X, 5, true);
    rig.img.set_bit(Area::Y, 6, true);
    rig.img.set_bit(Area::S, 7, true);
    rig.img.set_bit(Area::T, 8, true);
    rig.img.set_bit(Area::C, 9, true);
    rig.img.set_word(Area::R, 9, 0);
    rig.scan();
    for (std::uint32_t i = 4; i <= 8; ++i) EXPECT_EQ(rig.img.word(Area::R, i), i) << i;
    EXPECT_EQ(rig.img.word(Area::R, 9), 0);  // M1924 only in the first scan
}

TEST(Mov, SourcesAndDestinations) {
    Rig rig(
        "  - MOV: {s: K100, d: R10}\n"
        "  - MOV: {s: 0x1F, d: R11}\n"
        "  - MOV: {s: 1Fh, d: R12}\n"
        "  - MOV: {s: -1, d: R13}\n"
        "  - MOV: {s: 65535, d: R14}\n"
        "  - MOV: {s: TMR3, d: CTR5}\n"
        "  - MOV: {s: D3999, d: R8071}\n"
        "  - MOV: {s: 0xA5A5, d: WY0}\n"
        "  - MOV: {s: R20, d: WS984}\n"
        "  - MOV: {s: WX0, d: TMR255}\n");
    rig.img.set_word(Area::TV, 3, 333);
    rig.img.set_word(Area::D, 3999, 3999);
    rig.img.set_word(Area::R, 20, 0x8001);
    rig.img.write_word({Area::X, 0, true}, 0x00F0);
    rig.scan();
    EXPECT_EQ(rig.img.word(Area::R, 10), 100);
    EXPECT_EQ(rig.img.word(Area::R, 11), 0x1F);
    EXPECT_EQ(rig.img.word(Area::R, 12), 0x1F);
    EXPECT_EQ(rig.img.word(Area::R, 13), 0xFFFF);
    EXPECT_EQ(rig.img.word(Area::R, 14), 0xFFFF);
    EXPECT_EQ(rig.img.word(Area::CV, 5), 333);
    EXPECT_EQ(rig.img.word(Area::R, 8071), 3999);
    EXPECT_EQ(rig.img.read_word({Area::Y, 0, true}), 0xA5A5);
    EXPECT_TRUE(rig.img.bit(Area::Y, 0));
    EXPECT_FALSE(rig.img.bit(Area::Y, 1));
    EXPECT_TRUE(rig.img.bit(Area::Y, 15));
    EXPECT_TRUE(rig.img.bit(Area::S, 984));
    EXPECT_TRUE(rig.img.bit(Area::S, 999));
    EXPECT_FALSE(rig.img.bit(Area::S, 985));
    EXPECT_EQ(rig.img.word(Area::TV, 255), 0x00F0);
}

// C200-C255 are 32-bit: CTRn names counter n's (low) word, not word n of the value area.
TEST(Mov, CounterOperandsAddressTheirCounter) {
    Rig rig(
        "  - MOV: {s: CTR201, d: R1}\n"
        "  - MOV: {s: 7, d: CTR255}\n");
    rig.img.set_word(Area::CV, 201, 0x1111);  // C200 high word
    rig.img.set_word(Area::CV, 202, 0x2222);  // C201 low word
    rig.scan();
    EXPECT_EQ(rig.img.word(Area::R, 1), 0x2222);
    EXPECT_EQ(rig.img.word(Area::CV, 310), 7);
    expect_error("  - MOV: {s: CTR256, d: R1}\n", 3, 14, "MOV.s");
}

// Instructions run in program order within one scan.
TEST(Mov, ProgramOrderWithinAScan) {
    Rig rig(
        "  - MOV: {s: R1, d: R2}\n"
        "  - MOV: {s: R0, d: R1}\n");
    rig.img.set_word(Area::R, 0, 5);
    rig.scan();
    EXPECT_EQ(rig.img.word(Area::R, 1), 5);
    EXPECT_EQ(rig.img.word(Area::R, 2), 0);  // R1 was still 0 when the first MOV ran
    rig.scan();
    EXPECT_EQ(rig.img.word(Area::R, 2), 5);
}

// Operand errors: each names the operand's file:line:col (or the mnemonic's when absent).
TEST(Mov, OperandErrorsNameTheirPosition) {
    // Columns: "  - MOV: {" puts the first operand key at 11.
    expect_error("  - MOV: {en: R5, s: R1, d: R2}\n", 3, 15, "MOV.en: expected a bit device");
    expect_error("  - MOV: {en: 2, s: R1, d: R2}\n", 3, 15,
                 "MOV.en: a constant enable must be 0 or 1");
    expect_error("  - MOV: {en: WM0, s: R1, d: R2}\n", 3, 15, "MOV.en");
    expect_error("  - MOV: {en: M2002, s: R1, d: R2}\n", 3, 15, "MOV.en");
    expect_error("  - MOV: {s: R8072, d: R2}\n", 3, 14, "MOV.s");
    expect_error("  - MOV: {s: D4000, d: R2}\n", 3, 14, "MOV.s");
    expect_error("  - MOV: {s: WM1990, d: R2}\n", 3, 14, "MOV.s");  // M1990-M2005
    expect_error("  - MOV: {s: M5, d: R2}\n", 3, 14, "MOV.s");      // a bit is not a word
    expect_error("  - MOV: {s: Q5, d: R2}\n", 3, 14, "MOV.s");
    expect_error("  - MOV: {s: 70000, d: R2}\n", 3, 14, "MOV.s: constant out of 16-bit range");
    expect_error("  - MOV: {s: R1, d: 5}\n", 3, 21, "MOV.d");
    expect_error("  - MOV: {s: R1, d: M5}\n", 3, 21, "MOV.d");
    expect_error("  - MOV: {s: R1, d: X0}\n", 3, 21, "MOV.d");
    expect_error("  - MOV: {s: R1, d: WX0}\n", 3, 21, "MOV.d");  // inputs are not written
    expect_error("  - MOV: {s: R1, d: R8072}\n", 3, 21, "MOV.d");
    expect_error("  - MOV: {s: R1, d: WY250}\n", 3, 21, "MOV.d");  // Y250-Y265
    // Missing operands: at the mnemonic.
    expect_error("  - MOV: {d: R2}\n", 3, 5, "MOV.s: operand is required");
    expect_error("  - MOV: {s: R1}\n", 3, 5, "MOV.d: operand is required");
    // Unknown operands: at the key.
    expect_error("  - MOV: {s: R1, d: R2, n: 3}\n", 3, 28, "MOV: unknown operand 'n'");
    // Errors in later lines point there.
    expect_error("  - MOV: {s: R1, d: R2}\n  - MOV:\n      s: R1\n      d: Q2\n", 6, 10, "MOV.d");
}

// MOVP (`p: true`, the FX pulse form the VB manual's examples use: docs/profile-vb.md): D = S
// only in the scan in which EN turns ON.
TEST(Mov, PulseFormMovesOnlyOnTheRisingEdge) {
    Rig rig("  - MOV: {en: M0, s: R100, d: R7, p: true}\n");
    rig.img.set_word(Area::R, 100, 11);
    rig.scan();
    EXPECT_EQ(rig.img.word(Area::R, 7), 0);  // EN OFF
    rig.img.set_bit(Area::M, 0, true);
    rig.scan();
    EXPECT_EQ(rig.img.word(Area::R, 7), 11);
    rig.img.set_word(Area::R, 100, 22);
    rig.scan(3);
    EXPECT_EQ(rig.img.word(Area::R, 7), 11);  // EN held ON: no new edge
    rig.img.set_bit(Area::M, 0, false);
    rig.scan();
    rig.img.set_bit(Area::M, 0, true);
    rig.scan();
    EXPECT_EQ(rig.img.word(Area::R, 7), 22);
}

// Decision (docs/profile-vb.md): an EN already ON in the first scan is an edge, as for an FX2N
// switched to RUN; `p: false` is the plain MOV.
TEST(Mov, PulseFormFiresInTheFirstScanWhenEnIsOn) {
    Rig rig(
        "  - MOV: {s: 5, d: R1, p: yes}\n"
        "  - MOV: {en: 1, s: R9, d: R2, p: false}\n");
    rig.img.set_word(Area::R, 9, 9);
    rig.scan();
    EXPECT_EQ(rig.img.word(Area::R, 1), 5);
    rig.img.set_word(Area::R, 1, 0);
    rig.img.set_word(Area::R, 9, 10);
    rig.scan();
    EXPECT_EQ(rig.img.word(Area::R, 1), 0);
    EXPECT_EQ(rig.img.word(Area::R, 2), 10);
    expect_error("  - MOV: {s: R1, d: R2, p: 2}\n", 3, 28,
                 "MOV.p: expected true or false, got '2'");
}

TEST(Mov, UnknownInstructionNamesItsPosition) {
    expect_error("  - MOV: {s: R1, d: R2}\n  - FOO: {a: 1}\n", 4, 5, "unknown instruction 'FOO'");
}

}  // namespace
}  // namespace plcemu::instructions

namespace plcemu::instructions {
namespace {

// An operand of a megabyte is quoted in an excerpt, not echoed whole into the log.
TEST(Mov, OperandErrorsQuoteAnExcerptOfAHugeValue) {
    const std::string huge(1 << 20, 'Q');
    for (const std::string ops : {"s: HUGE, d: D0", "s: K1, d: HUGE", "en: HUGE, s: K1, d: D0"}) {
        SCOPED_TRACE(ops);
        std::string text = "  - MOV: {" + ops + "}\n";
        text.replace(text.find("HUGE"), 4, huge);
        const auto f = testing::config_failure([&] { Rig rig(text); });
        ASSERT_TRUE(f.thrown);
        EXPECT_LT(f.what.size(), 300u) << f.what.substr(0, 300);
        EXPECT_NE(f.what.find("QQQQ"), std::string::npos);
    }
}

}  // namespace
}  // namespace plcemu::instructions
