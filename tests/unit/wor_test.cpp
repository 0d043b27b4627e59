// WOR (FX FNC27, word OR, as the VB manual's examples use it: docs/profile-vb.md, "Program
// entries"): while EN is ON, D = S1 OR S2 each scan; S1, S2 words or constants, D a register or
// 16 bits; operand errors name their position.

#include <gtest/gtest.h>

#include <string>

#include "support/vb_plc.hpp"

namespace plcemu::instructions {
namespace {

using image::Area;
using testing::VbPlc;

TEST(Wor, OrsTwoWordsEveryScanWhileEnIsOn) {
    VbPlc p("  - WOR: {en: M0, s1: D0, s2: H00F0, d: D1}\n");
    p.set_word(Area::D, 0, 0x1203);
    p.set_word(Area::D, 1, 0x5555);
    p.scan();
    EXPECT_EQ(p.word(Area::D, 1), 0x5555);  // EN OFF: D kept
    p.set(Area::M, 0, true);
    p.scan();
    EXPECT_EQ(p.word(Area::D, 1), 0x12F3);
    p.set_word(Area::D, 0, 0x8000);
    p.scan();
    EXPECT_EQ(p.word(Area::D, 1), 0x80F0);
}

TEST(Wor, IntoSixteenOutputs) {
    VbPlc p("  - WOR: {s1: K1, s2: D5, d: WY10}\n");
    p.set_word(Area::D, 5, 0x8000);
    p.scan();
    EXPECT_TRUE(p.bit(Area::Y, 8));   // Y10
    EXPECT_TRUE(p.bit(Area::Y, 23));  // Y27
    EXPECT_FALSE(p.bit(Area::Y, 9));  // Y11
}

TEST(Wor, OperandErrorsNameTheirPosition) {
    using testing::expect_program_error;
    expect_program_error("  - WOR: {en: M0, s1: D0, s2: D1, d: K3}\n", 38, "WOR.d");
    expect_program_error("  - WOR: {en: M0, s1: R0, s2: D1, d: D2}\n", 23,
                         "WOR.s1: expected a register (D, TN, CN)");
    expect_program_error("  - WOR: {en: M0, s1: D0, s2: K70000, d: D2}\n", 31,
                         "WOR.s2: constant out of 16-bit range");
    expect_program_error("  - WOR: {en: M0, s1: D0, d: D2}\n", 5, "WOR.s2: operand is required");
}

}  // namespace
}  // namespace plcemu::instructions
