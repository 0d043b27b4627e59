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
