// FB temperature conversion (FB manual FUN72/FUN73, R4016–R4023; docs/profile-fb.md,
// "Conversion"): the emulated module's raw counts, the printed thermocouple formulas
// raw × m × R4016…R4019 / 1024, °F, the broken-thermocouple thresholds, the RTD model with α,
// line-resistance compensation (R4020/R4021) and R4022/R4023, the RTD raw value, averaging
// (R4015).

#include <gtest/gtest.h>

#include "plcemu/image/image.hpp"
#include "profiles/fb/conversion.hpp"
#include "support/profiles.hpp"

namespace plcemu::profiles::fb {
namespace {

using image::Area;

Factors defaults() { return Factors{}; }

// FB manual FUN73, R4016: "工程单位温度值 = (原始温度读值 × R4016) / 1024 (单极性)".
TEST(FbConversion, R4016KUnipolarFormula) {
    EXPECT_EQ(thermocouple_raw(200.0, tp::kK, 0), 826);  // round(200 × 1024 / 248)
    EXPECT_EQ(thermocouple_celsius(826, 1, tp::kK, 0, defaults()), 200);
    Factors f;
    f.k_positive = 258;  // a calibration: the reading changes, raw does not
    EXPECT_EQ(thermocouple_celsius(826, 1, tp::kK, 0, f), 208);
    f.k_positive = 238;
    EXPECT_EQ(thermocouple_celsius(826, 1, tp::kK, 0, f), 191);
    // 0~5 V is unipolar too: × 1.
    EXPECT_EQ(thermocouple_raw(455.0, tp::kK, 1), 1879);
    EXPECT_EQ(thermocouple_celsius(1879, 1, tp::kK, 1, defaults()), 455);
}

// R4018/R4019: the J factors.
TEST(FbConversion, R4018JFormula) {
    EXPECT_EQ(thermocouple_raw(300.0, tp::kJ, 0), 1280);
    EXPECT_EQ(thermocouple_celsius(1280, 1, tp::kJ, 0, defaults()), 300);
    Factors f;
    f.j_positive = 250;
    EXPECT_EQ(thermocouple_celsius(1280, 1, tp::kJ, 0, f), 312);
    EXPECT_EQ(thermocouple_raw(-50.0, tp::kJ, 2), -91);  // round(−50 × 1024 / (2 × 280))
}

// R4016 "× 2 (双极性)", R4017 "(-5~5V) × 1", "(-10~10V) × 2", read literally.
TEST(FbConversion, R4017BipolarFormulasLiterally) {
    EXPECT_EQ(thermocouple_raw(200.0, tp::kK, 2), 413);
    EXPECT_EQ(thermocouple_celsius(413, 1, tp::kK, 2, defaults()), 200);
    EXPECT_EQ(thermocouple_raw(-50.0, tp::kK, 2), -90);  // −89.5 rounds away from zero
    EXPECT_EQ(thermocouple_celsius(-90, 1, tp::kK, 2, defaults()), -50);
    Factors f;
    f.k_negative = 300;
    EXPECT_EQ(thermocouple_celsius(-90, 1, tp::kK, 2, f), -52);
    // −5~5 V: × 2 above 0, × 1 below, as printed.
    EXPECT_EQ(thermocouple_raw(-50.0, tp::kK, 3), -179);
    EXPECT_EQ(thermocouple_celsius(-179, 1, tp::kK, 3, defaults()), -49);  // trunc toward 0
    EXPECT_EQ(thermocouple_raw(100.0, tp::kK, 3), 206);
}

TEST(FbConversion, RawIsClampedToTheRangeCounts) {
    EXPECT_EQ(thermocouple_raw(5000.0, tp::kK, 0), 4095);
    EXPECT_EQ(thermocouple_raw(-20.0, tp::kK, 0), 0);
    EXPECT_EQ(thermocouple_raw(5000.0, tp::kK, 2), 2047);
    EXPECT_EQ(thermocouple_raw(-5000.0, tp::kK, 3), -2048);
    EXPECT_EQ(full_scale_raw(1), 4095);
    EXPECT_EQ(full_scale_raw(3), 2047);
}

// R4009: 0 °C, 1 °F.
TEST(FbConversion, R4009Fahrenheit) {
    Factors f;
    f.fahrenheit = true;
    EXPECT_EQ(thermocouple_display(200, f), 392);
    EXPECT_EQ(thermocouple_display(991, f), 1815);
    EXPECT_EQ(rtd_display(500, f), 1220);  // 50.0 °C = 122.0 °F
    image::Image img(testing::profile("fb").layout());
    img.set_word(Area::R, 4009, 1);
    EXPECT_TRUE(Factors::read(img).fahrenheit);
    img.set_word(Area::R, 4009, 2);  // any other value: °C
    EXPECT_FALSE(Factors::read(img).fahrenheit);
    img.set_word(Area::R, 4009, 0x0101);
    EXPECT_TRUE(Factors::read(img).fahrenheit);
}

// FUN73: "大于 900°C 或 1700°F" (10 V), 450 °C / 870 °F (5 V), strictly above.
TEST(FbConversion, BrokenThermocoupleThresholds) {
    const Factors c;
    Factors fa;
    fa.fahrenheit = true;
    EXPECT_FALSE(thermocouple_broken(900, 0, c));
    EXPECT_TRUE(thermocouple_broken(901, 2, c));
    EXPECT_TRUE(thermocouple_broken(991, 0, c));
    EXPECT_FALSE(thermocouple_broken(1688, 0, fa));  // 920 °C is not broken in °F
    EXPECT_TRUE(thermocouple_broken(1701, 2, fa));
    EXPECT_FALSE(thermocouple_broken(450, 1, c));
    EXPECT_TRUE(thermocouple_broken(451, 3, c));
    EXPECT_TRUE(thermocouple_broken(871, 1, fa));
    // A broken K on 0~10 V reads full scale: 991 °C with the default R4016, ≤ 900 with 225.
    EXPECT_EQ(thermocouple_celsius(4095, 1, tp::kK, 0, c), 991);
    Factors low;
    low.k_positive = 225;
    EXPECT_EQ(thermocouple_celsius(4095, 1, tp::kK, 0, low), 899);
}

// R4020 high byte (DIN/JIS), R4022: "PT-100 工程单位温度值 = (温度读值 × R4022) / 1024".
TEST(FbConversion, RtdModelAndR4022) {
    EXPECT_EQ(rtd_sample(50.0, 0.0, 0.0, tp::kPt100, 2, false), 500);
    EXPECT_EQ(rtd_celsius10(500, 1, tp::kPt100, defaults()), 500);
    EXPECT_EQ(rtd_raw(500, tp::kPt100, 2, false), 2081);
    Factors f;
    f.pt100 = 1034;
    EXPECT_EQ(rtd_celsius10(500, 1, tp::kPt100, f), 504);
    f.pt1000 = 2048;  // R4023 for the Pt1000 only
    EXPECT_EQ(rtd_celsius10(500, 1, tp::kPt1000, f), 1000);
    // JIS: α 0.00392 for the sensor and for the module.
    EXPECT_EQ(rtd_sample(50.0, 0.0, 4.0, tp::kPt100, 2, true), 398);
}

// R4020 low byte, R4021: the 3-wire line-resistance compensation in 0.1 Ω.
TEST(FbConversion, R4021LineResistanceCompensation) {
    EXPECT_EQ(rtd_sample(50.0, 0.0, 1.0, tp::kPt100, 2, false), 474);
    EXPECT_EQ(rtd_sample(50.0, 0.0, 4.0, tp::kPt100, 2, false), 396);
    EXPECT_EQ(rtd_sample(50.0, 1.5, 0.0, tp::kPt100, 2, false), 539);
    EXPECT_EQ(rtd_sample(50.0, 1.5, 1.5, tp::kPt100, 2, false), 500);  // compensated
    EXPECT_EQ(rtd_sample(50.0, 0.0, 1.0, tp::kPt1000, 2, false), 497);
    image::Image img(testing::profile("fb").layout());
    img.set_word(Area::R, 4020, 0x0001);
    img.set_word(Area::R, 4021, 5000);
    img.set_word(Area::R, 5003, 15);
    EXPECT_EQ(compensation_ohm(img, 3), 1.5);
    EXPECT_EQ(compensation_ohm(img, 0), 0.0);
    img.set_word(Area::R, 4020, 0x0002);       // the table in D
    EXPECT_EQ(compensation_ohm(img, 3), 0.0);  // D5003 does not exist: no compensation
    img.set_word(Area::R, 4021, 100);
    img.set_word(Area::D, 103, 20);
    EXPECT_EQ(compensation_ohm(img, 3), 2.0);
    img.set_word(Area::R, 4020, 0x0100);  // low byte 0: off
    EXPECT_EQ(compensation_ohm(img, 3), 0.0);
    img.set_word(Area::R, 4020, 0x0001);
    img.set_word(Area::R, 4021, 8071);
    EXPECT_EQ(compensation_ohm(img, 1), 0.0);  // R8072 is outside R
}

// The measuring ranges of FB-2AH(T)4 and -3 (FUN73): the ADC saturates at their ends.
TEST(FbConversion, RtdRangesClamp) {
    EXPECT_EQ(rtd_sample(200.0, 0.0, 0.0, tp::kPt100, 0, false), 1466);
    EXPECT_EQ(rtd_raw(1466, tp::kPt100, 0, false), 4095);
    EXPECT_EQ(rtd_sample(200.0, 0.0, 0.0, tp::kPt100Hi, 2, false), 2000);
    EXPECT_EQ(rtd_sample(-40.0, 0.0, 0.0, tp::kPt100, 1, false), -123);  // 5 V: −12.3 °C
    EXPECT_EQ(rtd_sample(-40.0, 0.0, 0.0, tp::kPt100, 3, true), -120);
    EXPECT_EQ(rtd_sample(300.0, 0.0, 0.0, tp::kPt1000Hi, 0, true), 2810);
    EXPECT_EQ(rtd_sample(0.0, 0.0, 0.0, tp::kPt1000Hi, 1, false), 55);
    EXPECT_EQ(rtd_raw(kRtdBroken, tp::kPt100, 0, false), 4095);
    EXPECT_FALSE(rtd_broken(9000));
    EXPECT_TRUE(rtd_broken(9001));
}

// R4015: 0 none, 1 two, 2 four, 3 eight, 4 sixteen; > 4 taken as 4.
TEST(FbConversion, R4015Averaging) {
    EXPECT_EQ(averaged_samples(0), 1);
    EXPECT_EQ(averaged_samples(1), 2);
    EXPECT_EQ(averaged_samples(2), 4);
    EXPECT_EQ(averaged_samples(3), 8);
    EXPECT_EQ(averaged_samples(4), 16);
    EXPECT_EQ(averaged_samples(9), 16);
    // The sum of n raws converts at once: m and F by the sign of the sum.
    EXPECT_EQ(thermocouple_celsius(826 + 830 + 822 + 826, 4, tp::kK, 0, defaults()), 200);
    EXPECT_EQ(thermocouple_celsius(-90 + 10, 2, tp::kK, 2, defaults()), -22);
}

}  // namespace
}  // namespace plcemu::profiles::fb
