// FROM and TO (docs/profile-vb.md, "Temperature modules": the VB manual's FNC88/FNC92 examples
// read the modules' buffer memory with FROM and set their modes with TO), on a VB PLC with its
// modules: n words moved, a constant S into all n, the pulse forms, and the operand error 6705
// for a module or word that does not exist.

#include <gtest/gtest.h>

#include "support/vb_plc.hpp"

namespace plcemu::instructions {
namespace {

using image::Area;
using testing::VbPlc;

constexpr const char* kModules = "modules: [VB-4T, VB-2PT]\n";

TEST(FromTo, FromCopiesNWordsFromM2On) {
    VbPlc p(
        "  - FROM: {en: M9000, m1: 1, m2: 0, d: D100, n: 4}\n"
        "  - FROM: {en: M9000, m1: 2, m2: 29, d: WM10, n: 1}\n",
        kModules);
    p.scan();
    EXPECT_EQ(p.d(100, 4), (std::vector<std::uint16_t>{7, 7, 7, 7}));  // the power-up modes
    EXPECT_TRUE(p.bit(Area::M, 24));                                   // CR#29 b14: ready
}

TEST(FromTo, ToWritesAConstantIntoAllNWords) {
    VbPlc p(
        "  - TO: {en: M0, m1: 1, m2: 1, s: K0, n: 3}\n"
        "  - FROM: {en: M9000, m1: 1, m2: 0, d: D100, n: 4}\n",
        kModules);
    p.set(Area::M, 0, true);
    p.scan();
    EXPECT_EQ(p.d(100, 4), (std::vector<std::uint16_t>{7, 0, 0, 0}));
}

TEST(FromTo, ToFromRegistersAndM1M2FromRegisters) {
    VbPlc p(
        "  - TO: {en: M9000, m1: D0, m2: D1, s: D10, n: 2}\n"
        "  - FROM: {en: M9000, m1: D0, m2: D1, d: D100, n: 2}\n",
        kModules);
    p.set_d(0, {2, 40});
    p.set_d(10, {1234, 0xFFFF});
    p.scan();
    EXPECT_EQ(p.d(100, 2), (std::vector<std::uint16_t>{1234, 0xFFFF}));
}

// p: true (FROMP, TOP): only in the scan in which EN turns ON.
TEST(FromTo, PulseFormMovesOnTheRisingEdgeOnly) {
    VbPlc p("  - FROM: {en: M0, m1: 1, m2: 40, d: D100, n: 1, p: true}\n", kModules);
    p.set(Area::M, 0, true);
    p.scan();
    EXPECT_EQ(p.word(Area::D, 100), 0);
    p.set_word(Area::D, 100, 55);
    p.scan();
    EXPECT_EQ(p.word(Area::D, 100), 55);  // EN still ON: nothing moved
    p.set(Area::M, 0, false);
    p.scan();
    p.set(Area::M, 0, true);
    p.scan();
    EXPECT_EQ(p.word(Area::D, 100), 0);
}

// A module not on the bus, or a word past CR#63: what came before moves, then 6705 in D9067,
// M9067 ON, the entry's step in D9069.
TEST(FromTo, NoSuchWordIsOperandError6705) {
    VbPlc p(
        "  - MOV: {en: M9000, s: K1, d: D0}\n"
        "  - FROM: {en: M0, m1: 3, m2: 0, d: D100, n: 1}\n"
        "  - TO: {en: M1, m1: 1, m2: 63, s: K0, n: 2}\n"
        "  - FROM: {en: M9000, m1: 1, m2: 63, d: D110, n: 1}\n",
        kModules);
    p.set_word(Area::D, 100, 99);
    p.set(Area::M, 0, true);
    p.scan();
    EXPECT_EQ(p.word(Area::D, 100), 99);
    EXPECT_EQ(p.word(Area::D, 9067), 6705);
    EXPECT_EQ(p.word(Area::D, 9069), 2);
    EXPECT_TRUE(p.bit(Area::M, 9067));
    p.set(Area::M, 0, false);
    p.set_word(Area::D, 9067, 0);
    p.set(Area::M, 1, true);
    p.scan();
    EXPECT_EQ(p.word(Area::D, 9067), 6705);
    EXPECT_EQ(p.word(Area::D, 9069), 3);
    EXPECT_EQ(p.word(Area::D, 110), 0);  // CR#63 was written before CR#64 failed
}

// A PLC without modules: every FROM/TO is 6705.
TEST(FromTo, NoModulesAtAll) {
    VbPlc p("  - FROM: {en: M9000, m1: 1, m2: 0, d: D100, n: 1}\n");
    p.scan();
    EXPECT_EQ(p.word(Area::D, 9067), 6705);
}

TEST(FromTo, OperandErrors) {
    testing::expect_program_error("  - FROM: {en: M0, m1: 1, m2: 0, d: D7999, n: 2}\n", 37,
                                  "D7999");
    testing::expect_program_error("  - FROM: {en: M0, m1: 1, m2: 0, d: D0, n: 513}\n", 44,
                                  "out of range 1..512");
    testing::expect_program_error("  - TO: {en: M0, m1: 1, m2: 0, s: D0, n: 1, p: maybe}\n", 48,
                                  "expected true or false");
    testing::expect_program_error("  - FROM: {en: M0, m1: 1, m2: 0, d: X0, n: 1}\n", 37,
                                  "got 'X0'");
    testing::expect_program_error("  - TO: {en: M0, m1: 1, m2: 0, s: D0, n: 1, q: 1}\n", 48,
                                  "unknown operand 'q'");
}

}  // namespace
}  // namespace plcemu::instructions
