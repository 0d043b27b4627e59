// Register image (docs/profile-fbs.md, The FBs profile; docs/operations.md, Retentive memory):
// areas, device names, word/bit access, retentive ranges.

#include <gtest/gtest.h>

#include "support/profiles.hpp"
#include "plcemu/image/image.hpp"

namespace plcemu::image {
namespace {

TEST(Image, FbsAreasHaveTheManualsSizes) {
    const Layout l = testing::fbs_layout();
    EXPECT_EQ(l.size_of(Area::X), 256u);
    EXPECT_EQ(l.size_of(Area::Y), 256u);
    EXPECT_EQ(l.size_of(Area::M), 2002u);
    EXPECT_EQ(l.size_of(Area::S), 1000u);
    EXPECT_EQ(l.size_of(Area::T), 256u);
    EXPECT_EQ(l.size_of(Area::C), 256u);
    EXPECT_EQ(l.size_of(Area::R), 8072u);  // R0-R8071
    EXPECT_EQ(l.size_of(Area::D), 4000u);
    EXPECT_EQ(l.size_of(Area::TV), 256u);
    EXPECT_EQ(l.size_of(Area::CV), 200u + 56u * 2u);  // C200-C255 are 32-bit
}

TEST(Image, ParsesDeviceNames) {
    EXPECT_EQ(testing::fbs_naming().parse_device("R100"), (Device{Area::R, 100, false}));
    EXPECT_EQ(testing::fbs_naming().parse_device("d0"), (Device{Area::D, 0, false}));
    EXPECT_EQ(testing::fbs_naming().parse_device("WM800"), (Device{Area::M, 800, true}));
    EXPECT_EQ(testing::fbs_naming().parse_device("TMR5"), (Device{Area::TV, 5, false}));
    EXPECT_EQ(testing::fbs_naming().parse_device("CTR200"), (Device{Area::CV, 200, false}));
    EXPECT_EQ(testing::fbs_naming().parse_device("T5"), (Device{Area::T, 5, false}));
    EXPECT_FALSE(testing::fbs_naming().parse_device("WR100"));  // a word of bits needs a bit area
    EXPECT_FALSE(testing::fbs_naming().parse_device("Q1"));
    EXPECT_FALSE(testing::fbs_naming().parse_device("R"));
    EXPECT_FALSE(testing::fbs_naming().parse_device("R1x"));
    EXPECT_EQ(testing::fbs_naming().parse_range("D100-D199"), (Range{Area::D, 100, 100}));
    EXPECT_EQ(testing::fbs_naming().parse_range("M5"), (Range{Area::M, 5, 1}));
    EXPECT_FALSE(testing::fbs_naming().parse_range("D100-R199"));
    EXPECT_FALSE(testing::fbs_naming().parse_range("D199-D100"));
}

TEST(Image, WordOfBitsIsLowBitFirst) {
    Image img(testing::fbs_layout());
    img.write_word({Area::M, 800, true}, 0x8005);
    EXPECT_TRUE(img.bit(Area::M, 800));
    EXPECT_FALSE(img.bit(Area::M, 801));
    EXPECT_TRUE(img.bit(Area::M, 802));
    EXPECT_TRUE(img.bit(Area::M, 815));
    EXPECT_EQ(img.read_word({Area::M, 800, true}), 0x8005);
}

// Where a range's devices lie in the block (the state file sums retentive ranges by it).
TEST(Image, ARangesExtentIsWhereItsDevicesLie) {
    const Layout l = testing::fbs_layout();
    Image img(l);
    const auto at = [&](const std::uint8_t* p) {
        return static_cast<std::size_t>(reinterpret_cast<const std::byte*>(p) -
                                        img.storage().data());
    };
    const auto words = Image::extent(l, {Area::R, 100, 3});
    EXPECT_EQ(words.offset, at(reinterpret_cast<const std::uint8_t*>(&img.words(Area::R)[100])));
    EXPECT_EQ(words.size, 6u);
    const auto bits = Image::extent(l, {Area::M, 800, 600});
    EXPECT_EQ(bits.offset, at(&img.bits(Area::M)[800]));
    EXPECT_EQ(bits.size, 600u);
    // Cut at the end of its area; past it, nothing.
    const auto cut = Image::extent(l, {Area::R, l.size_of(Area::R) - 2, 10});
    EXPECT_EQ(cut.size, 4u);
    EXPECT_EQ(Image::extent(l, {Area::R, l.size_of(Area::R), 1}).size, 0u);
    EXPECT_EQ(Image::extent(l, {Area::R, 0xFFFFFFF0u, 0x20}).size, 0u);
}

TEST(Image, ClearNonRetentiveKeepsOnlyRetentiveRanges) {
    // docs/operations.md, Retentive memory: M800-M1399, S500-S999, R0-R2999, D0-D3999, R5000-R8071,
    // C100-C139 and C200-C239 current values are retentive by default.
    const Layout l = testing::fbs_layout();
    Image img(l);
    img.set_bit(Area::M, 799, true);
    img.set_bit(Area::M, 800, true);
    img.set_bit(Area::M, 1399, true);
    img.set_bit(Area::M, 1400, true);
    img.set_word(Area::R, 2999, 7);
    img.set_word(Area::R, 3000, 7);
    img.set_word(Area::CV, 139, 7);
    img.set_word(Area::CV, 140, 7);
    img.set_word(Area::CV, 200 + 2 * 39 + 1, 7);  // C239 high word
    img.set_word(Area::CV, 200 + 2 * 40, 7);      // C240 low word
    img.set_bit(Area::Y, 0, true);
    img.clear_non_retentive(l.retentive);
    EXPECT_FALSE(img.bit(Area::M, 799));
    EXPECT_TRUE(img.bit(Area::M, 800));
    EXPECT_TRUE(img.bit(Area::M, 1399));
    EXPECT_FALSE(img.bit(Area::M, 1400));
    EXPECT_EQ(img.word(Area::R, 2999), 7);
    EXPECT_EQ(img.word(Area::R, 3000), 0);
    EXPECT_EQ(img.word(Area::CV, 139), 7);
    EXPECT_EQ(img.word(Area::CV, 140), 0);
    EXPECT_EQ(img.word(Area::CV, 279), 7);
    EXPECT_EQ(img.word(Area::CV, 280), 0);
    EXPECT_FALSE(img.bit(Area::Y, 0));
}

TEST(Image, RetentiveRangesAreContiguousInOneBlock) {
    // Persistence maps the whole block: each area (and so each retentive range) is one
    // contiguous run of the storage.
    const Layout l = testing::fbs_layout();
    Image img(l);
    auto* base = reinterpret_cast<std::uint8_t*>(img.storage().data());
    int bit_ranges = 0;
    int word_ranges = 0;
    for (const auto& r : l.retentive) {
        const std::size_t off = Image::area_offset(l, r.area);
        if (is_bit_area(r.area)) {
            EXPECT_EQ(img.bits(r.area), base + off);
            ++bit_ranges;
        } else {
            EXPECT_EQ(reinterpret_cast<std::uint8_t*>(img.words(r.area)), base + off);
            ++word_ranges;
        }
        EXPECT_LE(off + (r.end()) * (is_bit_area(r.area) ? 1u : 2u), img.storage().size());
    }
    // The FBs latches bits (M, S) and words (R, D): both kinds were checked.
    EXPECT_GT(bit_ranges, 0);
    EXPECT_GT(word_ranges, 0);
}

// docs/profile-fbs.md, The FBs profile and Modbus map: C200-C255 are 32-bit (two words, low word
// first), so counter n's value is not word n.
TEST(Image, CounterNamesGiveTheirWordIndex) {
    EXPECT_EQ(testing::fbs_naming().parse_device("CTR199"), (Device{Area::CV, 199, false}));
    EXPECT_EQ(testing::fbs_naming().parse_device("CTR200"), (Device{Area::CV, 200, false}));
    EXPECT_EQ(testing::fbs_naming().parse_device("CTR201"), (Device{Area::CV, 202, false}));
    EXPECT_EQ(testing::fbs_naming().parse_device("CTR255"), (Device{Area::CV, 310, false}));
    const Layout l = testing::fbs_layout();
    EXPECT_TRUE(l.contains({Area::CV, testing::fbs_naming().parse_device("CTR255")->index, 2}));
    EXPECT_FALSE(l.contains({Area::CV, testing::fbs_naming().parse_device("CTR256")->index, 1}));
    EXPECT_FALSE(testing::fbs_naming().parse_device("CTR4294967295"));
    // A range ending at a 32-bit counter takes its high word too.
    EXPECT_EQ(testing::fbs_naming().parse_range("CTR200-CTR239"), (Range{Area::CV, 200, 80}));
    EXPECT_EQ(testing::fbs_naming().parse_range("CTR100-CTR139"), (Range{Area::CV, 100, 40}));
    EXPECT_EQ(testing::fbs_naming().parse_range("CTR190-CTR200"), (Range{Area::CV, 190, 12}));
    EXPECT_EQ(testing::fbs_naming().parse_range("CTR255"), (Range{Area::CV, 310, 2}));
    EXPECT_EQ(testing::fbs_naming().format_range({Area::CV, 200, 80}), "CTR200-CTR239");
    EXPECT_EQ(testing::fbs_naming().format_range({Area::CV, 310, 2}), "CTR255");
    EXPECT_EQ(testing::fbs_naming().format_range({Area::D, 100, 100}), "D100-D199");
    EXPECT_EQ(testing::fbs_naming().format_range({Area::R, 4136, 1}), "R4136");
}

}  // namespace
}  // namespace plcemu::image
