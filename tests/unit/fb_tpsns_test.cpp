// FUN85 TPSNS (FB manual FUN85/FUN86; docs/profile-fb.md, "FUN85 TPSNS"): the FB-4AJ(K)xx's
// points read four at a time, one group every R4004 ms, raw into R3968+p, readings into TR+p,
// the four working words, ERR and ALM, EN off, and the load checks.

#include <gtest/gtest.h>

#include <string>

#include "plcemu/config/config.hpp"
#include "plcemu/daemon/plc.hpp"
#include "plcemu/plant/plant.hpp"
#include "profiles/fb/tpsns.hpp"
#include "support/plc_rig.hpp"
#include "support/config_errors.hpp"

namespace plcemu::profiles::fb {
namespace {

using image::Area;

const std::string kTpsns =
    "  - TPSNS: {en: M1, tp: 0, pl: 0, tr: R0, wr: R250, err: M120, alm: M121}\n";

// An FB PLC with `modules`; plant channels at 200 °C (k 0: nothing heats), channel 5 at 300 °C.
struct Rig : testing::PlcRig {
    explicit Rig(const std::string& program = kTpsns, const std::string& modules = "[FB-4AK24]")
        : PlcRig("profile: fb\nscan_ms: 10\ntemperature:\n  modules: " + modules +
                     "\nplant:\n  defaults: {k: 0, ambient: 200}\n  channels:\n"
                     "    5: {ambient: 300}\nprogram:\n" +
                     program,
                 "fb.yaml") {}
};

std::string program_with(const std::string& from, const std::string& to) {
    std::string p = kTpsns;
    return p.replace(p.find(from), from.size(), to);
}

// FB manual FUN85 (docs/profile-fb.md, "FUN85 TPSNS"): the four inputs sample in parallel, points
// 4g…4g+3 together, one group R4004 (333) ms after the one before.
TEST(FbTpsns, ParallelGroupsOfFourEveryR4004) {
    Rig rig;
    rig.set_m(1, true);
    rig.scan(34);  // 0…330 ms
    EXPECT_EQ(rig.r(252), 0);
    rig.scan();  // 340 ms ≥ 333: points 0-3 together
    EXPECT_EQ(rig.r(252), 0x000F);
    EXPECT_EQ(rig.r(0), 200);
    EXPECT_EQ(rig.r(4), 0);
    rig.scan(33);  // 670 ms ≥ 666: points 4-7
    EXPECT_EQ(rig.r(252), 0x00FF);
    EXPECT_EQ(rig.r(253), 0);
}

// ⌈N/4⌉ × R4004: 24 points in 6 × 333 = 1998 ms, and 6 × 166 = 996 ms with R4004 = 166; the round
// keeps its pace (point 0 again at 7 × 333 ms).
TEST(FbTpsns, RoundIsGroupsTimesR4004) {
    Rig rig;
    rig.set_m(1, true);
    rig.scan(200);  // 0…1990 ms
    EXPECT_EQ(rig.r(253), 0x000F);
    rig.scan();  // 2000 ms ≥ 1998: points 20-23
    EXPECT_EQ(rig.r(253), 0x00FF);
    rig.set_r(4016, 258);
    rig.scan(33);  // …2330 ms
    EXPECT_EQ(rig.r(0), 200);
    rig.scan();  // 2340 ms ≥ 2331: point 0 again
    EXPECT_EQ(rig.r(0), 208);

    Rig fast;
    fast.set_r(4004, 166);
    fast.set_m(1, true);
    fast.scan(100);
    EXPECT_EQ(fast.r(253), 0x000F);
    fast.scan();  // 1000 ms ≥ 996
    EXPECT_EQ(fast.r(253), 0x00FF);

    // An FB-4AK18: ⌈18/4⌉ = 5 groups, the last of two points; point 0 again at 6 × 333 ms.
    Rig eighteen(kTpsns, "[FB-4AK18]");
    eighteen.set_m(1, true);
    eighteen.scan(168);  // 1670 ms ≥ 1665
    EXPECT_EQ(eighteen.r(253), 0x0003);
    eighteen.set_r(4016, 258);
    eighteen.scan(32);
    EXPECT_EQ(eighteen.r(0), 200);
    eighteen.scan();  // 2000 ms ≥ 1998
    EXPECT_EQ(eighteen.r(0), 208);
}

// docs/profile-fb.md, "FUN85 TPSNS": with `temperature.modules` empty N is 24 — after a full round
// points 0-23 are read into R3968+p and TR+p and WR+3 (read once, points 16-23) is 00FFh.
TEST(FbTpsns, NoModulesMeasures24Points) {
    Rig rig(kTpsns, "[]");
    rig.set_m(1, true);
    rig.scan(201);
    EXPECT_EQ(rig.r(252), 0xFFFF);
    EXPECT_EQ(rig.r(253), 0x00FF);
    EXPECT_EQ(rig.r(3968 + 23), 826);
    EXPECT_EQ(rig.r(23), 200);
    EXPECT_EQ(rig.r(3968 + 24), 0);
    EXPECT_EQ(rig.r(24), 0);
}

// Raw values go to R3968+p and readings to TR+p (K, 0~10 V: 200 °C → 826 / 200, 300 °C → 1239 /
// 300); no relays or AR.
TEST(FbTpsns, RawIntoR3968PlusPReadingIntoTrPlusP) {
    Rig rig;
    rig.set_m(1, true);
    rig.scan(201);
    for (std::uint32_t p = 0; p < 24; ++p) {
        EXPECT_EQ(rig.r(3968 + p), p == 5 ? 1239 : 826) << p;
        EXPECT_EQ(rig.r(p), p == 5 ? 300 : 200) << p;
    }
    EXPECT_EQ(rig.r(3968 + 24), 0);
    EXPECT_EQ(rig.r(24), 0);
    EXPECT_EQ(rig.r(3842), 0);
    for (std::uint32_t y = 0; y < 64; ++y) EXPECT_FALSE(rig.plc.image().bit(Area::Y, y)) << y;
}

// WR+0/WR+1: broken points 0-15 / 16-23; WR+2/WR+3: read once. ALM = any broken. A point whose
// R4010/R4011 bit is 0 reads 0 and is never broken.
TEST(FbTpsns, WorkingWordsAndAlm) {
    Rig rig;
    rig.sensor_broken(17, true);
    rig.sensor_broken(2, true);
    rig.set_m(1, true);
    rig.scan(201);
    EXPECT_EQ(rig.r(250), 0x0004);
    EXPECT_EQ(rig.r(251), 0x0002);
    EXPECT_EQ(rig.r(252), 0xFFFF);
    EXPECT_EQ(rig.r(253), 0x00FF);
    EXPECT_EQ(rig.r(17), 991);
    EXPECT_EQ(rig.r(3968 + 17), 4095);
    EXPECT_TRUE(rig.m(121));
    rig.set_r(4010, 0xFFFB);
    rig.set_r(4011, 0xFFFD);
    rig.scan(200);
    EXPECT_EQ(rig.r(250), 0);
    EXPECT_EQ(rig.r(251), 0);
    EXPECT_EQ(rig.r(17), 0);
    EXPECT_FALSE(rig.m(121));
}

// tp other than 0 (K) or 1 (J), or pl outside 0-3: not executed, ERR ON, nothing written.
TEST(FbTpsns, ErrForTpOrPlOutOfRange) {
    for (const char* bad : {"tp: 2, pl: 0", "tp: 0, pl: 4", "tp: -1, pl: 0"}) {
        Rig rig(program_with("tp: 0, pl: 0", bad), "[]");
        rig.set_m(1, true);
        rig.scan(300);
        EXPECT_TRUE(rig.m(120)) << bad;
        EXPECT_EQ(rig.r(3968), 0) << bad;
        EXPECT_EQ(rig.r(0), 0) << bad;
        EXPECT_EQ(rig.r(252), 0) << bad;
    }
    Rig good;
    good.scan();
    EXPECT_FALSE(good.m(120));
}

// EN off: WR 0, ALM OFF, nothing read; TR and R3968+p keep their values; EN rising starts the
// round afresh.
TEST(FbTpsns, EnOff) {
    Rig rig;
    rig.sensor_broken(0, true);
    rig.set_m(1, true);
    rig.scan(201);
    EXPECT_TRUE(rig.m(121));
    rig.set_m(1, false);
    rig.scan();
    for (std::uint32_t w = 0; w < tpsns::kWorkingWords; ++w) EXPECT_EQ(rig.r(250 + w), 0) << w;
    EXPECT_FALSE(rig.m(121));
    EXPECT_EQ(rig.r(1), 200);
    EXPECT_EQ(rig.r(3968), 4095);
    rig.scan(300);
    EXPECT_EQ(rig.r(252), 0);
    rig.set_m(1, true);
    rig.scan(35);
    EXPECT_EQ(rig.r(252), 0x000F);
}

// Load checks: tp against the module's J/K type; the module's points size TR; a program with a
// TPSNS has no other TPSNS and no TP4/TSTC (the FB-4AJ(K)xx is used alone), named both ways; a
// TPSNS under FB-2A…4 modules.
TEST(FbTpsns, LoadChecks) {
    using testing::config_failure;
    using testing::expect_config_error;
    expect_config_error(config_failure([] { Rig rig(kTpsns, "[FB-4AJ24]"); }), "fb.yaml", 10, 25,
                        "0 (K) does not match the FB-4AJ24 at fb.yaml:4:13");
    EXPECT_NO_THROW(Rig(program_with("tp: 0", "tp: 1"), "[FB-4AJ12]"));
    // TR takes N words: R3828 has room for 12 before R3840, not for 24.
    EXPECT_NO_THROW(Rig(program_with("tr: R0", "tr: R3828"), "[FB-4AK12]"));
    expect_config_error(config_failure([] { Rig rig(program_with("tr: R0", "tr: R3828")); }),
                        "fb.yaml", 10, 39, "tr");
    expect_config_error(
        config_failure([] { Rig rig(kTpsns + program_with("wr: R250", "wr: R260")); }), "fb.yaml",
        11, 5, "at most one (one FB-4AJ(K)xx), the first is at fb.yaml:10:5");
    const std::string tp4 =
        "  - TP4: {en: M3, tp: 0, pl: 0, sm: 0, ym: Y16, ar: R3842, tr: R40, wr: R220}\n";
    expect_config_error(config_failure([&] { Rig rig(tp4 + kTpsns, "[]"); }), "fb.yaml", 11, 5,
                        "the TPSNS cannot be used with the TP4 at fb.yaml:10:5");
    expect_config_error(config_failure([&] { Rig rig(kTpsns + tp4, "[]"); }), "fb.yaml", 11, 5,
                        "the TP4 cannot be used with the TPSNS at fb.yaml:10:5");
    expect_config_error(config_failure([] { Rig rig(kTpsns, "[FB-2AK4]"); }), "fb.yaml", 10, 25,
                        "lists the FB-2AK4 at fb.yaml:4:13");
}

// Load checks (docs/profile-fb.md, "FUN85 TPSNS"): a TSTC, like a TP4, measures the FB-2A…4
// modules, which "cannot be used together with … FB-4AJ(K)xx" (FB manual FUN73): a program with
// a TSTC and a TPSNS is refused at the later entry, naming the other, in either order.
TEST(FbTpsns, LoadChecksTstcWithTpsns) {
    using testing::config_failure;
    using testing::expect_config_error;
    const std::string tstc =
        "  - TSTC: {en: M0, hc: 1, tp: 0, pl: 0, sm: 0, ym: Y16, ar: R3842, tr: R40, yh: Y48, "
        "sh: 0, zh: 4, sv: R100, os: R120, pr: R140, ir: R160, dr: R180, or: R300, wr: R200, "
        "err: M100, ao0: M101, ao1: M102}\n";
    EXPECT_NO_THROW(Rig(tstc, "[]"));
    expect_config_error(config_failure([&] { Rig rig(tstc + kTpsns, "[]"); }), "fb.yaml", 11, 5,
                        "the TPSNS cannot be used with the TSTC at fb.yaml:10:5");
    expect_config_error(config_failure([&] { Rig rig(kTpsns + tstc, "[]"); }), "fb.yaml", 11, 5,
                        "the TSTC cannot be used with the TPSNS at fb.yaml:10:5");
}

// Load checks on what it writes (docs/profile-fb.md, "FUN85 TPSNS"): TR, WR, ERR and ALM. ALM
// on its own ERR is refused; so, against a TPCTL ahead of it in the program (which loads: program
// order is not a rule), TR on the TPCTL's SV (settings it only reads), TR on its OR, WR on its WR
// and ERR on its ERR — at the TPSNS's operand, naming the TPCTL.
TEST(FbTpsns, LoadChecksWhatItWrites) {
    using testing::config_failure;
    using testing::expect_config_error;
    expect_config_error(config_failure([] { Rig rig(program_with("alm: M121", "alm: M120")); }),
                        "fb.yaml", 10, 69, "M120 overlaps its own err M120");
    const std::string tpctl =
        "  - TPCTL: {en: M0, hc: 1, yn: Y30, sn: 0, zn: 24, sv: R100, os: R130, pr: R160, "
        "ir: R190, dr: R220, or: R300, wr: R400, err: M100, alm: M101}\n";
    const auto with = [](std::string text, const std::string& from, const std::string& to) {
        return text.replace(text.find(from), from.size(), to);
    };
    EXPECT_NO_THROW(Rig(tpctl + kTpsns));
    const std::string same = "(two instructions may not write the same devices)";
    struct Case {
        std::string program;
        int col;
        std::string needle;
    };
    for (const Case& c : {
             Case{with(tpctl, "sv: R100", "sv: R0") + kTpsns, 39,
                  "R0-R23 overlaps R0-R23 of the TPCTL at fb.yaml:10:5 (it reads them as "
                  "settings, and this instruction writes them)"},
             Case{with(tpctl, "or: R300", "or: R10") + kTpsns, 39,
                  "R0-R23 overlaps R10-R33 of the TPCTL at fb.yaml:10:5 " + same},
             Case{with(tpctl, "wr: R400", "wr: R252") + kTpsns, 47,
                  "R250-R253 overlaps R252-R260 of the TPCTL at fb.yaml:10:5 " + same},
             Case{with(tpctl, "err: M100", "err: M120") + kTpsns, 58,
                  "M120 overlaps M120 of the TPCTL at fb.yaml:10:5 " + same},
         }) {
        expect_config_error(config_failure([&] { Rig rig(c.program); }), "fb.yaml", 11, c.col,
                            c.needle);
    }
}

}  // namespace
}  // namespace plcemu::profiles::fb
