// CMPOUT (the FX family's compare contacts LD=, LD<>, LD<, LD<=, LD>, LD>= driving an output, as
// the VB manual's examples use them: docs/profile-vb.md, "Program entries"): every scan OUT =
// S1 op S2 on signed 16-bit words; the manual's "< T200 D102" time-proportioning output; operand
// errors name their position.

#include <gtest/gtest.h>

#include <string>

#include "support/vb_plc.hpp"

namespace plcemu::instructions {
namespace {

using image::Area;
using testing::VbPlc;

TEST(CmpOut, EveryOperatorOnSignedWords) {
    // M0..M5: D0 op D1 for = <> < <= > >=.
    VbPlc p(
        "  - CMPOUT: {op: '=', s1: D0, s2: D1, out: M0}\n"
        "  - CMPOUT: {op: '<>', s1: D0, s2: D1, out: M1}\n"
        "  - CMPOUT: {op: '<', s1: D0, s2: D1, out: M2}\n"
        "  - CMPOUT: {op: '<=', s1: D0, s2: D1, out: M3}\n"
        "  - CMPOUT: {op: '>', s1: D0, s2: D1, out: M4}\n"
        "  - CMPOUT: {op: '>=', s1: D0, s2: D1, out: M5}\n");
    struct Case {
        std::uint16_t a, b;
        bool eq, ne, lt, le, gt, ge;
    };
    const Case cases[] = {
        {5, 5, true, false, false, true, false, true},
        {0xFFFF, 1, false, true, true, true, false, false},  // −1 < 1: signed, not 65535 > 1
        {0x8000, 0x7FFF, false, true, true, true, false, false},
        {7, 0xFFF9, false, true, false, false, true, true},  // 7 > −7
    };
    for (const auto& c : cases) {
        SCOPED_TRACE(std::to_string(c.a) + " vs " + std::to_string(c.b));
        p.set_word(Area::D, 0, c.a);
        p.set_word(Area::D, 1, c.b);
        p.scan();
        EXPECT_EQ(p.bit(Area::M, 0), c.eq);
        EXPECT_EQ(p.bit(Area::M, 1), c.ne);
        EXPECT_EQ(p.bit(Area::M, 2), c.lt);
        EXPECT_EQ(p.bit(Area::M, 3), c.le);
        EXPECT_EQ(p.bit(Area::M, 4), c.gt);
        EXPECT_EQ(p.bit(Area::M, 5), c.ge);
    }
}

TEST(CmpOut, ConstantsAndTimerValues) {
    VbPlc p("  - CMPOUT: {op: '>=', s1: TN5, s2: K-3, out: Y0}\n");
    p.set_word(Area::TV, 5, 0xFFFC);  // −4
    p.scan();
    EXPECT_FALSE(p.bit(Area::Y, 0));
    p.set_word(Area::TV, 5, 0xFFFD);
    p.scan();
    EXPECT_TRUE(p.bit(Area::Y, 0));
}

// VB manual FNC92 example I: T200 K500 is a 5 s cycle and "< T200 D102" switches Y0 for the first
// D102 counts of it (a time-proportioning output). The timer restarts itself here with RST.
TEST(CmpOut, ManualsTimeProportioningOutput) {
    VbPlc p(
        "  - TMR: {en: M9000, t: T200, k: 500}\n"
        "  - RST: {en: T200, d: T200}\n"
        "  - CMPOUT: {op: '<', s1: TN200, s2: D102, out: Y0}\n");
    p.set_word(Area::D, 102, 150);
    int on = 0;
    for (int i = 0; i < 1000; ++i) {
        p.scan();
        on += p.bit(Area::Y, 0) ? 1 : 0;
    }
    EXPECT_EQ(on, 300);  // 30 % of two 5 s cycles
    p.set_word(Area::D, 102, 0);
    p.scan(2);
    EXPECT_FALSE(p.bit(Area::Y, 0));
}

TEST(CmpOut, OperandErrorsNameTheirPosition) {
    using testing::expect_program_error;
    expect_program_error("  - CMPOUT: {op: '=<', s1: D0, s2: D1, out: Y0}\n", 18,
                         "CMPOUT.op: expected one of = <> < <= > >=, got '=<'");
    // The manual writes the timer's value with the contact's name; a VB config spells it TN200.
    expect_program_error(
        "  - CMPOUT: {op: '<', s1: T200, s2: D102, out: Y0}\n", 27,
        "CMPOUT.s1: 'T200' is not a word operand of this PLC (its value is TN200)");
    expect_program_error("  - CMPOUT: {op: '<', s1: C210, s2: D102, out: Y0}\n", 27,
                         "(its value is CN210)");
    expect_program_error("  - CMPOUT: {op: '<', s1: D0, s2: D1, out: X0}\n", 44,
                         "CMPOUT.out: expected a Y, M or S output, got 'X0'");
    expect_program_error("  - CMPOUT: {s1: D0, s2: D1, out: Y0}\n", 5,
                         "CMPOUT.op: operand is required");
    expect_program_error("  - CMPOUT: {en: M0, op: '<', s1: D0, s2: D1, out: Y0}\n", 18,
                         "CMPOUT: unknown operand 'en'");
}

}  // namespace
}  // namespace plcemu::instructions
