// CMP (the FX family's FNC10, as the VB runs it: docs/profile-vb.md, "Program entries"): D, D+1,
// D+2 say S1 > S2, S1 = S2, S1 < S2 (signed) while EN is ON and keep their state while it is
// OFF; operand errors name their position (its pulse form: listing_test.cpp).

#include <gtest/gtest.h>

#include <array>
#include <string>
#include <utility>

#include "support/vb_plc.hpp"

namespace plcemu::instructions {
namespace {

using image::Area;
using testing::VbPlc;

TEST(Cmp, ThreeRelaysSaySignedGreaterEqualLess) {
    VbPlc p("  - CMP: {en: M0, s1: D0, s2: K-3, d: M10}\n");
    p.set(Area::M, 0, true);
    const std::pair<int, std::array<bool, 3>> cases[] = {{-4, {false, false, true}},
                                                         {-3, {false, true, false}},
                                                         {100, {true, false, false}},
                                                         {-32768, {false, false, true}}};
    for (const auto& [v, want] : cases) {
        p.set_d(0, {static_cast<std::uint16_t>(v)});
        p.scan();
        EXPECT_EQ(p.bit(Area::M, 10), want[0]) << v;
        EXPECT_EQ(p.bit(Area::M, 11), want[1]) << v;
        EXPECT_EQ(p.bit(Area::M, 12), want[2]) << v;
    }
    p.set(Area::M, 0, false);
    p.set_d(0, {static_cast<std::uint16_t>(-3)});
    p.scan();
    EXPECT_FALSE(p.bit(Area::M, 11));  // EN OFF: the last result stays
    EXPECT_TRUE(p.bit(Area::M, 12));
}

TEST(Cmp, OperandErrorsNameTheirPosition) {
    using testing::expect_program_error;
    expect_program_error("  - CMP: {en: M0, s1: D0, s2: D1, d: X0}\n", 38, "CMP.d");
    expect_program_error("  - CMP: {en: M0, s1: D0, s2: D1, d: M9254}\n", 38, "CMP.d");
    expect_program_error("  - CMP: {en: M0, s1: D0, d: M0}\n", 5, "CMP.s2: operand is required");
}

}  // namespace
}  // namespace plcemu::instructions
