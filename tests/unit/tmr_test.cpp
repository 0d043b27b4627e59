// TMR (the FX family's on-delay timer, as the VB manual's examples use it: docs/profile-vb.md,
// "Program entries"): while EN is ON the time since the previous scan counts in the timer's
// time base up to K, the contact is ON from K on; EN OFF clears a timer and leaves a retentive
// one as it is; K is a constant or a word device; the VB's time bases per timer number.

#include <gtest/gtest.h>

#include <string>

#include "support/vb_plc.hpp"

namespace plcemu::instructions {
namespace {

using image::Area;
using testing::VbPlc;

// VB manual FNC88 example: "T0 K20" is a 2 seconds delay (100 ms timer, 10 ms scans).
TEST(Tmr, OnDelayContactComesOnWhenTheValueReachesK) {
    VbPlc p("  - TMR: {en: M0, t: T0, k: 20}\n");
    p.set(Area::M, 0, true);
    p.scan(199);
    EXPECT_EQ(p.word(Area::TV, 0), 19);
    EXPECT_FALSE(p.bit(Area::T, 0));
    p.scan();
    EXPECT_EQ(p.word(Area::TV, 0), 20);
    EXPECT_TRUE(p.bit(Area::T, 0));
    p.scan(500);
    EXPECT_EQ(p.word(Area::TV, 0), 20);  // the value stops at K
    EXPECT_TRUE(p.bit(Area::T, 0));
}

TEST(Tmr, EnOffClearsValueAndContact) {
    VbPlc p("  - TMR: {en: M0, t: T5, k: 3}\n");
    p.set(Area::M, 0, true);
    p.scan(40);
    EXPECT_TRUE(p.bit(Area::T, 5));
    p.set(Area::M, 0, false);
    p.scan();
    EXPECT_EQ(p.word(Area::TV, 5), 0);
    EXPECT_FALSE(p.bit(Area::T, 5));
}

// docs/profile-vb.md, "Device areas": T0–T199 100 ms, T200–T245 10 ms, T246–T249 1 ms,
// T250–T255 100 ms.
TEST(Tmr, TimeBaseFollowsTheTimerNumber) {
    VbPlc p(
        "  - TMR: {en: M0, t: T199, k: 1000}\n"
        "  - TMR: {en: M0, t: T200, k: 1000}\n"
        "  - TMR: {en: M0, t: T245, k: 1000}\n"
        "  - TMR: {en: M0, t: T246, k: 1000}\n"
        "  - TMR: {en: M0, t: T249, k: 1000}\n"
        "  - TMR: {en: M0, t: T250, k: 1000}\n"
        "  - TMR: {en: M0, t: T255, k: 1000}\n");
    p.set(Area::M, 0, true);
    p.scan(30);  // 300 ms
    EXPECT_EQ(p.word(Area::TV, 199), 3);
    EXPECT_EQ(p.word(Area::TV, 200), 30);
    EXPECT_EQ(p.word(Area::TV, 245), 30);
    // A 1 ms timer steps by the scan interval.
    EXPECT_EQ(p.word(Area::TV, 246), 300);
    EXPECT_EQ(p.word(Area::TV, 249), 300);
    EXPECT_EQ(p.word(Area::TV, 250), 3);
    EXPECT_EQ(p.word(Area::TV, 255), 3);
}

TEST(Tmr, TimeBelowOneCountCarriesToTheNextScan) {
    // 3 ms scans on a 10 ms timer: 10 scans are 30 ms, three counts, not ten times nothing.
    VbPlc p("  - TMR: {en: M0, t: T200, k: 1000}\n", "scan_ms: 3\n");
    p.set(Area::M, 0, true);
    p.scan(10);
    EXPECT_EQ(p.word(Area::TV, 200), 3);
}

TEST(Tmr, RetentiveTimerKeepsValueAndContactWhileEnIsOff) {
    VbPlc p(
        "  - TMR: {en: M0, t: T250, k: 20}\n"
        "  - RST: {en: M1, d: T250}\n");
    p.set(Area::M, 0, true);
    p.scan(100);  // 1 s
    EXPECT_EQ(p.word(Area::TV, 250), 10);
    p.set(Area::M, 0, false);
    p.scan(50);
    EXPECT_EQ(p.word(Area::TV, 250), 10);  // kept, not counting
    p.set(Area::M, 0, true);
    p.scan(100);
    EXPECT_EQ(p.word(Area::TV, 250), 20);  // the two seconds add up
    EXPECT_TRUE(p.bit(Area::T, 250));
    p.set(Area::M, 0, false);
    p.scan(10);
    EXPECT_TRUE(p.bit(Area::T, 250));
    EXPECT_EQ(p.word(Area::TV, 250), 20);
    // Only a RST clears it.
    p.set(Area::M, 1, true);
    p.scan();
    EXPECT_FALSE(p.bit(Area::T, 250));
    EXPECT_EQ(p.word(Area::TV, 250), 0);
}

TEST(Tmr, KFromARegisterIsReadEveryScan) {
    VbPlc p("  - TMR: {en: M0, t: T200, k: D10}\n");
    p.set_word(Area::D, 10, 50);
    p.set(Area::M, 0, true);
    p.scan(30);
    EXPECT_FALSE(p.bit(Area::T, 200));
    p.set_word(Area::D, 10, 20);  // lowered below the value: the contact comes on
    p.scan();
    EXPECT_TRUE(p.bit(Area::T, 200));
    EXPECT_EQ(p.word(Area::TV, 200), 30);  // above K: kept as it is
    // A negative K (0FFFFh) is below any value: ON, nothing else happens.
    p.set_word(Area::D, 10, 0xFFFF);
    p.scan();
    EXPECT_TRUE(p.bit(Area::T, 200));
    EXPECT_EQ(p.word(Area::TV, 200), 30);
}

TEST(Tmr, KZeroIsOnAsSoonAsEnIs) {
    VbPlc p("  - TMR: {en: M0, t: T0, k: K0}\n");
    p.scan();
    EXPECT_FALSE(p.bit(Area::T, 0));
    p.set(Area::M, 0, true);
    p.scan();
    EXPECT_TRUE(p.bit(Area::T, 0));
}

TEST(Tmr, AValueWrittenFromOutsideCountsOnFromThere) {
    // A master writes TN0 while the timer runs; the maximum value counts up to a K of 32767.
    VbPlc p("  - TMR: {en: M0, t: T0, k: 32767}\n");
    p.set(Area::M, 0, true);
    p.scan(25);
    EXPECT_EQ(p.word(Area::TV, 0), 2);
    p.set_word(Area::TV, 0, 32760);
    p.scan(100);
    EXPECT_EQ(p.word(Area::TV, 0), 32767);
    EXPECT_TRUE(p.bit(Area::T, 0));
    // A negative value written counts up towards K as well.
    p.set_word(Area::TV, 0, 0xFFFE);
    p.scan(10);
    EXPECT_EQ(p.word(Area::TV, 0), 0xFFFF);
    EXPECT_FALSE(p.bit(Area::T, 0));
}

TEST(Tmr, OperandErrorsNameTheirPosition) {
    using testing::expect_program_error;
    expect_program_error("  - TMR: {en: M0, t: D0, k: 20}\n", 22,
                         "TMR.t: expected 1 consecutive device(s) in T, got 'D0'");
    expect_program_error("  - TMR: {en: M0, t: TN0, k: 20}\n", 22, "TMR.t");
    expect_program_error("  - TMR: {en: M0, t: T256, k: 20}\n", 22, "TMR.t");
    expect_program_error("  - TMR: {en: M0, t: T0, k: 40000}\n", 29,
                         "TMR.k: 40000 is out of range 0..32767");
    expect_program_error("  - TMR: {en: M0, t: T0, k: K-1}\n", 29, "TMR.k");
    expect_program_error("  - TMR: {en: M0, t: T0, k: D8000}\n", 29, "TMR.k");
    expect_program_error("  - TMR: {en: M0, k: 20}\n", 5, "TMR.t: operand is required");
    expect_program_error("  - TMR: {en: M0, t: T0, k: 20, p: true}\n", 36,
                         "TMR: unknown operand 'p'");
}

}  // namespace
}  // namespace plcemu::instructions
