// How --print-map and --export-tags name a device in FATEK's protocol (docs/profile-fbs.md,
// "FATEK protocol", device names): the prefix and the zero-padded number a master writes.

#include "plcemu/fatek/device_name.hpp"

#include <gtest/gtest.h>

#include <string>

#include "support/profiles.hpp"

namespace plcemu::fatek {
namespace {

using image::Area;

// On an FBs: C0-C199 16-bit, C200-C255 32-bit.
std::string name(Area area, std::uint32_t index, bool word_of_bits = false) {
    static const image::Layout fbs = testing::fbs_layout();
    return device_name(fbs, area, index, word_of_bits);
}

TEST(FatekDeviceName, EachAreaAsAMasterWritesIt) {
    EXPECT_EQ(name(Area::X, 0), "X0000");
    EXPECT_EQ(name(Area::Y, 30), "Y0030");
    EXPECT_EQ(name(Area::M, 1926), "M1926");
    EXPECT_EQ(name(Area::S, 999), "S0999");
    EXPECT_EQ(name(Area::T, 5), "T0005");
    EXPECT_EQ(name(Area::C, 255), "C0255");
    EXPECT_EQ(name(Area::R, 100), "R00100");
    EXPECT_EQ(name(Area::R, 4055), "R04055");
    EXPECT_EQ(name(Area::D, 3999), "D03999");
    EXPECT_EQ(name(Area::TV, 5), "RT0005");
    EXPECT_EQ(name(Area::CV, 7), "RC0007");
}

// C200-C255 are 32-bit counters: named once, at their low word; the high word has no name.
TEST(FatekDeviceName, ThirtyTwoBitCountersAreNamedAtTheirLowWord) {
    EXPECT_EQ(name(Area::CV, 199), "RC0199");
    EXPECT_EQ(name(Area::CV, 200), "DRC0200");
    EXPECT_EQ(name(Area::CV, 201), "");
    EXPECT_EQ(name(Area::CV, 202), "DRC0201");
    EXPECT_EQ(name(Area::CV, 310), "DRC0255");
}

// A word of 16 discretes is a W form, which the protocol has at multiples of 8 only.
TEST(FatekDeviceName, WordsOfDiscretesAreWFormsAtMultiplesOfEight) {
    EXPECT_EQ(name(Area::M, 800, true), "WM0800");
    EXPECT_EQ(name(Area::Y, 8, true), "WY0008");
    EXPECT_EQ(name(Area::M, 801, true), "");
}

// A number wider than the name's digits has no name.
TEST(FatekDeviceName, NumbersPastTheDigitsHaveNoName) {
    EXPECT_EQ(name(Area::M, 9999), "M9999");
    EXPECT_EQ(name(Area::M, 10000), "");
    EXPECT_EQ(name(Area::R, 65535), "R65535");
    EXPECT_EQ(name(Area::R, 100000), "");
}

}  // namespace
}  // namespace plcemu::fatek
