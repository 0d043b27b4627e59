// CNT (the FX family's counter, as the VB writes it: docs/profile-vb.md): each OFF→ON of EN
// counts; a 16-bit counter stops at K, a 32-bit one counts up or down by its direction relay and
// wraps; the contact is ON while the value is at least K; K is a constant or a word device.

#include <gtest/gtest.h>

#include <string>

#include "plcemu/config/config.hpp"
#include "plcemu/daemon/plc.hpp"
#include "plcemu/image/image.hpp"
#include "support/config_errors.hpp"
#include "support/plc_rig.hpp"

namespace plcemu::instructions {
namespace {

using image::Area;

// A VB PLC running `program` (YAML list entries, one per line), stepped scan by scan.
struct Rig : testing::PlcRig {
    explicit Rig(const std::string& program)
        : PlcRig("profile: vb\nprogram:\n" + program, "c.yaml") {}
    void pulse(std::uint32_t bit, int n = 1) {
        for (int i = 0; i < n; ++i) {
            set_m(bit, true);
            scan();
            set_m(bit, false);
            scan();
        }
    }
    std::uint16_t cv(std::uint32_t i) { return word(Area::CV, i); }
    bool contact(std::uint32_t c) { return bit(Area::C, c); }
};

TEST(Cnt, SixteenBitCounterCountsRisingEdgesAndStopsAtK) {
    Rig rig("  - CNT: {en: M0, c: C5, k: 3}\n");
    rig.plc.image().set_bit(Area::M, 0, true);
    rig.plc.engine().run_scans(5);  // held ON: one edge only
    EXPECT_EQ(rig.cv(5), 1);
    EXPECT_FALSE(rig.contact(5));
    rig.plc.image().set_bit(Area::M, 0, false);
    rig.plc.engine().run_scans(1);
    rig.pulse(0, 4);
    EXPECT_EQ(rig.cv(5), 3);  // stops at K
    EXPECT_TRUE(rig.contact(5));
}

// A 16-bit value is signed, as a timer's is (docs/profile-vb.md): one a master writes negative
// counts up towards K with the contact OFF. Read unsigned, FFFFh was 65,535, over any K: the
// contact came ON and the counter never counted again.
TEST(Cnt, ANegativeValueAMasterWroteCountsUpTowardsK) {
    Rig rig("  - CNT: {en: M0, c: C0, k: 5}\n");
    rig.plc.image().set_word(Area::CV, 0, 0xFFFF);
    rig.scan();
    EXPECT_FALSE(rig.contact(0));
    rig.pulse(0, 2);
    EXPECT_EQ(rig.cv(0), 1);
    rig.plc.image().set_word(Area::CV, 0, 0x8000);
    rig.pulse(0);
    EXPECT_EQ(rig.cv(0), 0x8001);
    EXPECT_FALSE(rig.contact(0));
}

TEST(Cnt, KFromARegister) {
    Rig rig("  - CNT: {en: M0, c: C0, k: D10}\n");
    rig.plc.image().set_word(Area::D, 10, 2);
    rig.pulse(0);
    EXPECT_FALSE(rig.contact(0));
    rig.pulse(0);
    EXPECT_TRUE(rig.contact(0));
    EXPECT_EQ(rig.cv(0), 2);
}

TEST(Cnt, ThirtyTwoBitCounterCountsDownWhileItsDirectionRelayIsOn) {
    // C200 takes CV words 200 (low) and 201 (high); M9200 is its direction.
    Rig rig("  - CNT: {en: M0, c: C200, k: 2}\n");
    rig.pulse(0, 2);
    EXPECT_EQ(rig.cv(200), 2);
    EXPECT_TRUE(rig.contact(200));
    rig.plc.image().set_bit(Area::M, 9200, true);
    rig.pulse(0, 3);  // 2 → −1
    EXPECT_EQ(rig.cv(200), 0xFFFF);
    EXPECT_EQ(rig.cv(201), 0xFFFF);
    EXPECT_FALSE(rig.contact(200));
}

TEST(Cnt, CountersBeyondC234HaveNoDirectionRelay) {
    // M9200–M9234 steer C200–C234 only (docs/profile-vb.md): M9235 is plain storage, so C235
    // (CV words 270 and 271) counts up.
    Rig rig("  - CNT: {en: M0, c: C235, k: 2}\n");
    rig.plc.image().set_bit(Area::M, 9235, true);
    rig.pulse(0, 2);
    EXPECT_EQ(rig.cv(270), 2);
    EXPECT_EQ(rig.cv(271), 0);
    EXPECT_TRUE(rig.contact(235));
}

TEST(Cnt, OperandErrorsNameTheirPosition) {
    auto error = [](const std::string& program) {
        return testing::config_failure([&] { Rig rig(program); });
    };
    testing::expect_config_error(error("  - CNT: {en: M0, c: D5, k: 3}\n"), "c.yaml", 3, 22,
                                 "CNT.c");
    testing::expect_config_error(error("  - CNT: {en: M0, c: C5, k: 40000}\n"), "c.yaml", 3, 29,
                                 "CNT.k: 40000 is out of range 0..32767");
    testing::expect_config_error(
        error("  - CNT: {en: X8, c: C5, k: 3}\n"), "c.yaml", 3, 15,
        "CNT.en: expected a bit device (X, Y, M, S, T, C) or 0/1, got 'X8' (X and Y are numbered "
        "in octal: 7 is followed by 10)");
}

}  // namespace
}  // namespace plcemu::instructions
