// RST (the FX family's reset, as the VB manual's examples use it: docs/profile-vb.md, "Program
// entries"): in every scan while EN is ON, a timer or counter loses contact and value (a 32-bit
// counter both words), a relay goes OFF, a register becomes 0; operand errors name their
// position.

#include <gtest/gtest.h>

#include <string>

#include "support/vb_plc.hpp"

namespace plcemu::instructions {
namespace {

using image::Area;
using testing::VbPlc;

TEST(Rst, ResetsATimersContactAndValue) {
    VbPlc p(
        "  - TMR: {en: M0, t: T3, k: 5}\n"
        "  - RST: {en: M1, d: T3}\n");
    p.set(Area::M, 0, true);
    p.scan(60);
    EXPECT_TRUE(p.bit(Area::T, 3));
    p.set(Area::M, 1, true);
    p.scan();
    EXPECT_FALSE(p.bit(Area::T, 3));
    EXPECT_EQ(p.word(Area::TV, 3), 0);
}

// Decision (docs/profile-vb.md): RST of a 32-bit counter clears both words of its value.
TEST(Rst, ResetsBothWordsOfA32BitCounterAndItsContact) {
    VbPlc p(
        "  - CNT: {en: M0, c: C200, k: 1}\n"
        "  - RST: {en: M1, d: C200}\n");
    p.set_word(Area::CV, 200, 0x1234);  // CN200 low word
    p.set_word(Area::CV, 201, 0x0005);  // high word
    p.scan();
    EXPECT_TRUE(p.bit(Area::C, 200));
    p.set(Area::M, 1, true);
    p.scan();
    EXPECT_EQ(p.word(Area::CV, 200), 0);
    EXPECT_EQ(p.word(Area::CV, 201), 0);
    EXPECT_FALSE(p.bit(Area::C, 200));
    EXPECT_EQ(p.word(Area::CV, 202), 0);  // C201 untouched (it was 0 and stays 0)
}

TEST(Rst, HoldsACounterAtZeroWhileEnIsOn) {
    VbPlc p(
        "  - CNT: {en: M0, c: C7, k: 10}\n"
        "  - RST: {en: M1, d: C7}\n");
    p.set_word(Area::CV, 6, 99);  // C6, next to it, is left alone
    p.set(Area::M, 1, true);
    for (int i = 0; i < 3; ++i) {
        p.set(Area::M, 0, true);
        p.scan();
        p.set(Area::M, 0, false);
        p.scan();
    }
    EXPECT_EQ(p.word(Area::CV, 7), 0);
    EXPECT_EQ(p.word(Area::CV, 6), 99);
    p.set(Area::M, 1, false);
    p.set(Area::M, 0, true);
    p.scan();
    EXPECT_EQ(p.word(Area::CV, 7), 1);
}

TEST(Rst, SwitchesARelayOffAndClearsARegister) {
    VbPlc p(
        "  - RST: {en: M1, d: Y17}\n"
        "  - RST: {en: M1, d: S600}\n"
        "  - RST: {en: M1, d: D300}\n");
    p.set(Area::Y, 15, true);
    p.set(Area::S, 600, true);
    p.set_word(Area::D, 300, 777);
    p.scan();
    EXPECT_TRUE(p.bit(Area::Y, 15));  // EN OFF: nothing
    EXPECT_EQ(p.word(Area::D, 300), 777);
    p.set(Area::M, 1, true);
    p.scan();
    EXPECT_FALSE(p.bit(Area::Y, 15));
    EXPECT_FALSE(p.bit(Area::S, 600));
    EXPECT_EQ(p.word(Area::D, 300), 0);
}

TEST(Rst, OperandErrorsNameTheirPosition) {
    using testing::expect_program_error;
    expect_program_error("  - RST: {en: M1, d: X0}\n", 22,
                         "RST.d: expected 1 consecutive device(s) in Y, M, S, T, C, D, got 'X0'");
    expect_program_error("  - RST: {en: M1, d: K5}\n", 22, "RST.d");
    expect_program_error("  - RST: {en: M1, d: D8000}\n", 22, "RST.d");
    expect_program_error("  - RST: {en: M1, d: WM0}\n", 22, "RST.d");
    expect_program_error("  - RST: {en: X8, d: M0}\n", 15, "X and Y are numbered in octal");
}

}  // namespace
}  // namespace plcemu::instructions

namespace plcemu::instructions {
namespace {

// FX manual FNC40 ZRST: every device from D1 to D2 reset as RST resets one.
TEST(Zrst, ResetsAZoneOfRelaysTimersCountersAndRegisters) {
    VbPlc p(
        "  - ZRST: {en: M0, d1: M10, d2: M12}\n"
        "  - ZRST: {en: M0, d1: D5, d2: D7}\n"
        "  - ZRST: {en: M0, d1: C200, d2: C201}\n"
        "  - ZRST: {en: M0, d1: T1, d2: T2}\n");
    for (std::uint32_t i = 9; i <= 13; ++i) p.set(Area::M, i, true);
    p.set_d(4, {1, 2, 3, 4, 5});
    p.set(Area::C, 201, true);
    p.set(Area::T, 2, true);
    p.set_word(Area::TV, 2, 9);
    for (std::uint32_t w = 200; w <= 204; ++w) p.set_word(Area::CV, w, 7);  // C200–C202, 32-bit
    p.scan();
    EXPECT_TRUE(p.bit(Area::M, 10));  // EN OFF: nothing
    p.set(Area::M, 0, true);
    p.scan();
    EXPECT_TRUE(p.bit(Area::M, 9));
    EXPECT_FALSE(p.bit(Area::M, 10));
    EXPECT_FALSE(p.bit(Area::M, 12));
    EXPECT_TRUE(p.bit(Area::M, 13));
    EXPECT_EQ(p.d(4, 5), (std::vector<std::uint16_t>{1, 0, 0, 0, 5}));
    EXPECT_FALSE(p.bit(Area::C, 201));
    for (std::uint32_t w = 200; w <= 203; ++w) EXPECT_EQ(p.word(Area::CV, w), 0) << w;
    EXPECT_EQ(p.word(Area::CV, 204), 7);  // C202 is outside the zone
    EXPECT_FALSE(p.bit(Area::T, 2));
    EXPECT_EQ(p.word(Area::TV, 2), 0);
}

TEST(Zrst, PulseFormAndOperandErrors) {
    VbPlc p("  - ZRST: {en: M0, d1: D0, d2: D1, p: true}\n");
    p.set(Area::M, 0, true);
    p.set_d(0, {5, 5});
    p.scan();
    EXPECT_EQ(p.d(0, 2), (std::vector<std::uint16_t>{0, 0}));
    p.set_d(0, {6, 6});
    p.scan();
    EXPECT_EQ(p.d(0, 2), (std::vector<std::uint16_t>{6, 6}));  // EN still ON: no new edge
    using testing::expect_program_error;
    expect_program_error("  - ZRST: {en: M0, d1: M5, d2: D9}\n", 32,
                         "ZRST.d2: must be in the area of d1");
    expect_program_error("  - ZRST: {en: M0, d1: M5, d2: M4}\n", 32,
                         "ZRST.d2: must not come before d1");
    expect_program_error("  - ZRST: {en: M0, d1: X0, d2: X7}\n", 24, "ZRST.d1");
    // A zone through numbers the VB has no device for would clear the special relays beyond
    // them (M9000-) in mid-scan; D0-D9255 was refused as "D0 has no value".
    expect_program_error("  - ZRST: {en: M0, d1: M0, d2: M9255}\n", 24,
                         "ZRST.d1: M0-M9255 runs through M3072-M8999, which this PLC does not "
                         "have");
    expect_program_error("  - ZRST: {en: M0, d1: D0, d2: D9255}\n", 24,
                         "ZRST.d1: D0-D9255 runs through D8000-D8999");
}

}  // namespace
}  // namespace plcemu::instructions
