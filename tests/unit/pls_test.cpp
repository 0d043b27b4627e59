// PLS (the FX family's pulse, as the VB manual's examples use it: docs/profile-vb.md, "Program
// entries"): D is ON for the one scan in which EN turns ON; an EN already ON in the first scan is
// an edge; operand errors name their position.

#include <gtest/gtest.h>

#include <string>

#include "support/vb_plc.hpp"

namespace plcemu::instructions {
namespace {

using image::Area;
using testing::VbPlc;

TEST(Pls, OnForOneScanOnTheRisingEdge) {
    VbPlc p("  - PLS: {en: M0, d: M10}\n");
    p.scan();
    EXPECT_FALSE(p.bit(Area::M, 10));
    p.set(Area::M, 0, true);
    p.scan();
    EXPECT_TRUE(p.bit(Area::M, 10));
    p.scan();
    EXPECT_FALSE(p.bit(Area::M, 10));  // EN still ON: no new edge
    p.set(Area::M, 10, true);          // a master's write is overwritten
    p.scan();
    EXPECT_FALSE(p.bit(Area::M, 10));
    p.set(Area::M, 0, false);
    p.scan();
    p.set(Area::M, 0, true);
    p.scan();
    EXPECT_TRUE(p.bit(Area::M, 10));
}

// Decision (docs/profile-vb.md): the remembered input is OFF at start, as on an FX2N switched to
// RUN, so an input ON in the first scan pulses.
TEST(Pls, InputOnInTheFirstScanIsAnEdge) {
    VbPlc p("  - PLS: {en: M9000, d: Y0}\n");
    p.scan();
    EXPECT_TRUE(p.bit(Area::Y, 0));
    p.scan();
    EXPECT_FALSE(p.bit(Area::Y, 0));
}

TEST(Pls, OperandErrorsNameTheirPosition) {
    using testing::expect_program_error;
    expect_program_error("  - PLS: {en: M0, d: X0}\n", 22,
                         "PLS.d: expected a Y, M or S output, got 'X0'");
    expect_program_error("  - PLS: {en: M0, d: D0}\n", 22, "PLS.d");
    expect_program_error("  - PLS: {en: M0}\n", 5, "PLS.d: operand is required");
}

}  // namespace
}  // namespace plcemu::instructions
