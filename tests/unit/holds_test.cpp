// Discretes a master disabled (FATEK command 42; docs/profile-fbs.md, "FATEK protocol"), kept as
// two bitsets per bit area: discretes in different words and areas, across a word's edge, up to
// the last of an area.

#include <gtest/gtest.h>

#include "plcemu/engine/holds.hpp"
#include "plcemu/image/image.hpp"
#include "support/profiles.hpp"

namespace plcemu::engine {
namespace {

using image::Area;

TEST(Holds, EachDisabledDiscreteKeepsItsOwnValueAcrossWordsAndAreas) {
    const image::Layout layout = testing::fbs_layout();
    image::Image img(layout);
    Holds h(layout);
    const std::uint32_t last_m = layout.size_of(Area::M) - 1;
    // S63 and S64 sit either side of a word's edge; M100 and the last M in words of their own.
    for (auto [area, i] : {std::pair{Area::S, 63U}, std::pair{Area::S, 64U},
                           std::pair{Area::M, 100U}, std::pair{Area::M, last_m}}) {
        EXPECT_TRUE(h.set(area, i, true));
    }
    EXPECT_FALSE(h.set(Area::M, last_m + 1, true));  // past the area
    EXPECT_TRUE(h.held(Area::S, 64));
    EXPECT_FALSE(h.held(Area::S, 65));
    EXPECT_FALSE(h.held(Area::M, 99));
    EXPECT_FALSE(h.held(Area::Y, 100));  // same index, another area

    img.set_bit(Area::S, 63, true);  // what the master left
    img.set_bit(Area::M, last_m, true);
    h.take(img);
    // The scan writes every discrete...
    for (auto [area, i] : {std::pair{Area::S, 63U}, std::pair{Area::S, 64U},
                           std::pair{Area::M, 100U}, std::pair{Area::M, last_m}}) {
        img.set_bit(area, i, !img.bit(area, i));
    }
    img.set_bit(Area::S, 65, true);
    h.put(img);
    // ...and the disabled ones are as the master left them; the others as the scan wrote.
    EXPECT_TRUE(img.bit(Area::S, 63));
    EXPECT_FALSE(img.bit(Area::S, 64));
    EXPECT_FALSE(img.bit(Area::M, 100));
    EXPECT_TRUE(img.bit(Area::M, last_m));
    EXPECT_TRUE(img.bit(Area::S, 65));

    // Enabled again, one by one: the others stay held.
    EXPECT_TRUE(h.set(Area::S, 63, false));
    EXPECT_TRUE(h.set(Area::S, 63, false));  // already enabled: nothing changes
    EXPECT_FALSE(h.empty());
    img.set_bit(Area::S, 63, false);
    img.set_bit(Area::S, 64, true);
    h.put(img);
    EXPECT_FALSE(img.bit(Area::S, 63));  // no longer put back
    EXPECT_FALSE(img.bit(Area::S, 64));  // still held at what was taken
    h.clear();
    EXPECT_TRUE(h.empty());
    EXPECT_FALSE(h.held(Area::M, last_m));
}

TEST(Holds, ADiscreteDisabledAgainStartsFromZeroUntilTaken) {
    const image::Layout layout = testing::fbs_layout();
    image::Image img(layout);
    Holds h(layout);
    h.set(Area::Y, 5, true);
    img.set_bit(Area::Y, 5, true);
    h.take(img);
    h.set(Area::Y, 5, false);
    h.set(Area::Y, 5, true);  // its value from before is not kept
    h.put(img);
    EXPECT_FALSE(img.bit(Area::Y, 5));
}

}  // namespace
}  // namespace plcemu::engine
