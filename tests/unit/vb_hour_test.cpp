// FNC169 HOUR / DHOUR (VB manual FNC169, "Hour Meter"; docs/profile-vb.md, "FNC169 HOUR"): one
// test per rule — hours in D1 and seconds in D1+1 (DHOUR: hours in D1, D1+1, seconds in D1+2),
// the alarm D2 at hours ≥ S, counting past the alarm, EN OFF keeps everything, the sub-second
// remainder kept between scans, the stop at the register's maximum, written seconds ≥ 3600
// normalised, written hours taken as they are, retention following D1's area, operand errors.

#include <gtest/gtest.h>

#include <cstdint>
#include <string>
#include <vector>

#include "plcemu/daemon/plc.hpp"
#include "plcemu/image/image.hpp"
#include "support/vb_plc.hpp"

namespace plcemu::profiles::vb {
namespace {

using image::Area;
using testing::VbPlc;
using W = std::vector<std::uint16_t>;

// One scan a second makes an hour 3600 scans.
const std::string kSecondScans = "scan_ms: 1000\n";

// VB manual FNC169 and scenario "HOUR" of docs/profile-vb.md: S = 2 h.
TEST(Hour, HoursInD1SecondsInD1Plus1AndTheAlarmAtThePreset) {
    VbPlc p("  - HOUR: {en: M0, s: 2, d1: D7000, d2: Y0}\n", kSecondScans);
    p.set(Area::M, 0, true);
    p.scan(5400);  // 1.5 h
    EXPECT_EQ(p.d(7000, 2), (W{1, 1800}));
    EXPECT_FALSE(p.bit(Area::Y, 0));
    p.scan(1799);
    EXPECT_EQ(p.d(7000, 2), (W{1, 3599}));
    EXPECT_FALSE(p.bit(Area::Y, 0));
    p.scan();  // 2 h
    EXPECT_EQ(p.d(7000, 2), (W{2, 0}));
    EXPECT_TRUE(p.bit(Area::Y, 0));
}

// VB manual FNC169: counting continues after D2 turns ON.
TEST(Hour, CountingContinuesAfterTheAlarm) {
    VbPlc p("  - HOUR: {en: M0, s: K1, d1: D7000, d2: M5}\n", kSecondScans);
    p.set(Area::M, 0, true);
    p.scan(3600 * 3 + 10);
    EXPECT_EQ(p.d(7000, 2), (W{3, 10}));
    EXPECT_TRUE(p.bit(Area::M, 5));
}

// Decision (docs/profile-vb.md): the alarm is hours ≥ S, not = S, so that a preset changed below
// the count still alarms, and a preset raised above it clears the alarm.
TEST(Hour, AlarmIsHoursAtLeastAPresetFromARegister) {
    VbPlc p("  - HOUR: {en: M0, s: D10, d1: D7000, d2: Y1}\n", kSecondScans);
    p.set_word(Area::D, 10, 10);
    p.set(Area::M, 0, true);
    p.scan(3600 * 3);
    EXPECT_FALSE(p.bit(Area::Y, 1));
    p.set_word(Area::D, 10, 2);
    p.scan();
    EXPECT_TRUE(p.bit(Area::Y, 1));
    p.set_word(Area::D, 10, 4);
    p.scan();
    EXPECT_FALSE(p.bit(Area::Y, 1));
    // A negative preset (a master's 0FFFFh) is below any count: the alarm is ON.
    p.set_word(Area::D, 10, 0xFFFF);
    p.scan();
    EXPECT_TRUE(p.bit(Area::Y, 1));
}

// VB manual FNC169: "retentive function for the current value": EN OFF keeps D1, D1+1 and D2.
TEST(Hour, EnOffKeepsTheCountAndTheAlarm) {
    VbPlc p("  - HOUR: {en: M0, s: D10, d1: D7000, d2: Y1}\n", kSecondScans);
    p.set_word(Area::D, 10, 1);
    p.set(Area::M, 0, true);
    p.scan(3600 + 5);
    EXPECT_TRUE(p.bit(Area::Y, 1));
    p.set(Area::M, 0, false);
    p.set_word(Area::D, 10, 100);  // not looked at while EN is OFF
    p.scan(1000);
    EXPECT_EQ(p.d(7000, 2), (W{1, 5}));
    EXPECT_TRUE(p.bit(Area::Y, 1));
    p.set(Area::M, 0, true);
    p.scan(2);
    EXPECT_EQ(p.word(Area::D, 7001), 7);  // counts on from where it stopped
    EXPECT_FALSE(p.bit(Area::Y, 1));
}

// VB manual FNC169: the meter counts time, so scans shorter than a second add up.
TEST(Hour, TimeBelowASecondIsKeptBetweenScans) {
    VbPlc p("  - HOUR: {en: M0, s: 1, d1: D100, d2: M1}\n", "scan_ms: 300\n");
    p.set(Area::M, 0, true);
    p.scan(3);  // 0.9 s
    EXPECT_EQ(p.word(Area::D, 101), 0);
    p.scan();  // 1.2 s
    EXPECT_EQ(p.word(Area::D, 101), 1);
    p.set(Area::M, 0, false);  // the 0.2 s stay through EN OFF
    p.scan(5);
    p.set(Area::M, 0, true);
    p.scan(6);  // 0.2 + 1.8 s
    EXPECT_EQ(p.word(Area::D, 101), 3);
}

// VB manual FNC169: the count stops at the 16-bit maximum, 32767 h 3599 s.
TEST(Hour, StopsAtThe16BitMaximum) {
    VbPlc p("  - HOUR: {en: M0, s: 32767, d1: D7000, d2: Y0}\n", kSecondScans);
    p.set_d(7000, {32767, 3597});
    p.set(Area::M, 0, true);
    p.scan(10);
    EXPECT_EQ(p.d(7000, 2), (W{32767, 3599}));
    EXPECT_TRUE(p.bit(Area::Y, 0));
    // Seconds written beyond the maximum stop there too.
    p.set_word(Area::D, 7001, 65535);
    p.scan();
    EXPECT_EQ(p.d(7000, 2), (W{32767, 3599}));
}

// Decision (docs/profile-vb.md): written seconds of 3600 or more go into the hours at the next
// execution; written hours are taken as they are, even negative ones.
TEST(Hour, WrittenSecondsAreNormalisedWrittenHoursTakenAsTheyAre) {
    VbPlc p("  - HOUR: {en: M0, s: 1, d1: D7000, d2: Y0}\n", kSecondScans);
    p.set_d(7000, {4, 7300});  // 2 h 100 s
    p.scan();
    EXPECT_EQ(p.d(7000, 2), (W{4, 7300}));  // EN OFF: left as written
    p.set(Area::M, 0, true);
    p.scan();
    EXPECT_EQ(p.d(7000, 2), (W{6, 101}));
    p.set_d(7000, {0xFFFF, 3598});  // −1 h
    p.scan();
    EXPECT_EQ(p.d(7000, 2), (W{0xFFFF, 3599}));
    EXPECT_FALSE(p.bit(Area::Y, 0));
    p.scan();
    EXPECT_EQ(p.d(7000, 2), (W{0, 0}));
}

// DHOUR: hours in (D1+1, D1), low word first; seconds in D1+2; a 32-bit preset.
TEST(Hour, DhourKeeps32BitHoursLowWordFirst) {
    VbPlc p("  - DHOUR: {en: M0, s: 65536, d1: D7000, d2: Y0}\n", kSecondScans);
    p.set_d(7000, {0xFFFF, 0, 3599});  // 65535 h 3599 s
    p.set(Area::M, 0, true);
    p.scan();
    EXPECT_EQ(p.d(7000, 3), (W{0, 1, 0}));
    EXPECT_TRUE(p.bit(Area::Y, 0));  // 65536 h
}

TEST(Hour, DhourPresetFromTwoRegistersAndStopAtThe32BitMaximum) {
    VbPlc p("  - DHOUR: {en: M0, s: D10, d1: D7000, d2: Y0}\n", kSecondScans);
    p.set_d(10, {0xFFFF, 0x7FFF});  // 7FFFFFFFh h
    p.set_d(7000, {0xFFFF, 0x7FFF, 3598});
    p.set(Area::M, 0, true);
    p.scan(5);
    EXPECT_EQ(p.d(7000, 3), (W{0xFFFF, 0x7FFF, 3599}));
    EXPECT_TRUE(p.bit(Area::Y, 0));
}

// VB manual FNC169: retention follows D1's area. D7000 is latched (D200–D7999), D100 is not;
// the sub-second remainder is lost.
TEST(Hour, RetentionAcrossARestartFollowsD1sArea) {
    const std::string program =
        "  - HOUR: {en: M0, s: 5, d1: D7000, d2: M600}\n"
        "  - HOUR: {en: M0, s: 5, d1: D100, d2: M1}\n";
    const auto config = config::parse_config("profile: vb\nprogram:\n" + program, "vb.yaml");
    std::vector<std::byte> storage(image::Image::storage_size(daemon::plc_layout(config)));
    {
        VbPlc p(program, "", storage, daemon::Start::Fresh);
        p.set(Area::M, 0, true);
        p.scan(3600 * 100 + 150);  // 1 h 1 s 500 ms at 10 ms scans
        EXPECT_EQ(p.d(7000, 2), (W{1, 1}));
        EXPECT_EQ(p.word(Area::D, 100), 1);
    }
    VbPlc p(program, "", storage, daemon::Start::Retained);
    EXPECT_EQ(p.d(7000, 2), (W{1, 1}));
    EXPECT_EQ(p.d(100, 2), (W{0, 0}));
    p.set(Area::M, 0, true);
    p.scan(50);  // 0.5 s: the 0.5 s before the restart did not survive it
    EXPECT_EQ(p.word(Area::D, 7001), 1);
    p.scan(50);
    EXPECT_EQ(p.word(Area::D, 7001), 2);
}

TEST(Hour, OperandErrorsNameTheirPosition) {
    using testing::expect_program_error;
    expect_program_error("  - HOUR: {en: M0, s: 40000, d1: D0, d2: Y0}\n", 23,
                         "HOUR.s: 40000 is out of range 0..32767");
    expect_program_error("  - HOUR: {en: M0, s: K-1, d1: D0, d2: Y0}\n", 23, "HOUR.s");
    expect_program_error("  - HOUR: {en: M0, s: 1, d1: TN0, d2: Y0}\n", 30,
                         "HOUR.d1: expected 2 word(s) in D, got 'TN0'");
    // D1 and D1+1 must exist: D7999 is followed by the hole D8000–D8999.
    expect_program_error("  - HOUR: {en: M0, s: 1, d1: D7999, d2: Y0}\n", 30, "HOUR.d1");
    expect_program_error("  - DHOUR: {en: M0, s: 1, d1: D7998, d2: Y0}\n", 31,
                         "DHOUR.d1: expected 3 word(s) in D");
    expect_program_error("  - DHOUR: {en: M0, s: D7999, d1: D0, d2: Y0}\n", 24,
                         "DHOUR.s: expected 2 word(s) in D");
    expect_program_error("  - HOUR: {en: M0, s: 1, d1: D0, d2: X0}\n", 38,
                         "HOUR.d2: expected a Y, M or S output, got 'X0'");
    expect_program_error("  - HOUR: {en: M0, s: 1, d1: D0}\n", 5, "HOUR.d2: operand is required");
}

}  // namespace
}  // namespace plcemu::profiles::vb
