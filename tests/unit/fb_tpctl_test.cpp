// The FB's FUN86 TPCTL (FB manual FUN86; docs/profile-fb.md, "FUN86 TPCTL"): PID on TPSNS's
// readings, ERR for Sn/Zn at run time, the first-execution gains by TPSNS's Pl, R4005's FB codes
// in WR+4, the nine working words, R4013 B0–B7, R4006/R4007/R4008, EN off and TPSNS's EN off,
// the plant's drive, and the load checks.

#include <gtest/gtest.h>

#include <string>

#include "plcemu/config/config.hpp"
#include "plcemu/daemon/plc.hpp"
#include "plcemu/plant/plant.hpp"
#include "profiles/fb/tpctl.hpp"
#include "support/plc_rig.hpp"
#include "support/config_errors.hpp"

namespace plcemu::profiles::fb {
namespace {

using image::Area;

std::string tpsns(const std::string& pl = "pl: 0") {
    return "  - TPSNS: {en: M1, tp: 0, " + pl + ", tr: R0, wr: R250}\n";
}

std::string tpctl(const std::string& points = "sn: 0, zn: 24") {
    return "  - TPCTL: {en: M0, hc: 1, yn: Y30, " + points +
           ", sv: R300, os: R330, pr: R360, ir: R390, dr: R420, or: R450, wr: R480, err: M100, "
           "alm: M101}\n";
}

// `text` with its first `from` replaced by `to`.
std::string with(std::string text, const std::string& from, const std::string& to) {
    return text.replace(text.find(from), from.size(), to);
}

// `text`, a tpctl(), with the blocks it writes moved clear of tpctl()'s (PR…WR to R500…R580,
// Yn to Y60, ERR and ALM to M110 and M111) and its SV and OS kept.
std::string elsewhere(std::string text) {
    for (const auto& [from, to] : {std::pair<std::string, std::string>{"Y30", "Y60"},
                                   {"pr: R360", "pr: R500"},
                                   {"ir: R390", "ir: R520"},
                                   {"dr: R420", "dr: R540"},
                                   {"or: R450", "or: R560"},
                                   {"wr: R480", "wr: R580"},
                                   {"M100", "M110"},
                                   {"M101", "M111"}}) {
        text = with(text, from, to);
    }
    return text;
}

// An FB PLC with an FB-4AK24 (or `modules`) whose plant channels sit at `ambient` °C; `plant`
// replaces the defaults line.
struct Rig : testing::PlcRig {
    explicit Rig(const std::string& program = tpsns() + tpctl(),
                 const std::string& modules = "[FB-4AK24]",
                 const std::string& plant = "  defaults: {k: 0, ambient: 200}\n")
        : PlcRig("profile: fb\nscan_ms: 10\ntemperature:\n  modules: " + modules + "\nplant:\n" +
                     plant + "program:\n" + program,
                 "fb.yaml") {}
    void set_block(std::uint32_t at, int v, int n = 24) { PlcRig::set_block(at, v, n); }
    /// SP `sp`, offset 5, Kc `kc`, Ti `ti`, Td 0; both ENs on and the 24 points read (scan 200).
    void start(int sp, int kc = 60, int ti = 17) {
        set_block(300, sp);
        set_block(330, 5);
        set_block(360, kc);
        set_block(390, ti);
        set_block(420, 0);
        set_m(0, true);
        set_m(1, true);
        scan(201);
    }
};

// A tpctl("sn: 4, zn: 2"): SP 201 (E = 1 °C on the 200 °C readings), offset 5, Kc 60, Ti 17,
// Td 0, both ENs on, no scan yet.
void enable_sp_201_on_points_4_5(Rig& rig) {
    rig.set_block(300, 201, 2);
    rig.set_block(330, 5, 2);
    rig.set_block(360, 60, 2);
    rig.set_block(390, 17, 2);
    rig.set_m(0, true);
    rig.set_m(1, true);
}

// FB manual FUN86 with FUN73's first execution: every point whose PR is 0 gets Kc by TPSNS's
// Pl (60/30/120/60), Ti 17, Td 100; a nonzero PR is kept with its Ti and Td.
TEST(FbTpctl, FirstExecutionDefaultsByTpsnsPl) {
    struct Case {
        const char* pl;
        int kc;
    };
    for (const Case& c :
         {Case{"pl: 0", 60}, Case{"pl: 1", 30}, Case{"pl: 2", 120}, Case{"pl: 3", 60}}) {
        Rig rig(tpsns(c.pl) + tpctl());
        rig.set_r(361, 77);
        rig.scan(5);
        EXPECT_EQ(rig.r(360), 0) << "EN off: nothing given yet";
        rig.set_m(0, true);
        rig.scan();
        EXPECT_EQ(rig.r(360), c.kc) << c.pl;
        EXPECT_EQ(rig.r(383), c.kc) << c.pl;
        EXPECT_EQ(rig.r(390), 17) << c.pl;
        EXPECT_EQ(rig.r(420), 100) << c.pl;
        EXPECT_EQ(rig.r(361), 77) << c.pl;
        EXPECT_EQ(rig.r(391), 0) << c.pl;
    }
}

// FB manual FUN86: "Sn = 0〜23", "1 ≤ Zn ≤ 24 and 1 ≤ Sn+Zn ≤ 24": outside, not executed and ERR
// ON at run time, never a config error.
TEST(FbTpctl, ErrForSnZnOutOfRange) {
    for (const char* bad :
         {"sn: 20, zn: 5", "sn: 24, zn: 1", "sn: 0, zn: 0", "sn: 0, zn: 25", "sn: -1, zn: 4"}) {
        Rig rig(tpsns() + tpctl(bad), "[]");
        rig.set_m(0, true);
        rig.set_m(1, true);
        rig.scan(300);
        EXPECT_TRUE(rig.m(100)) << bad;
        EXPECT_FALSE(rig.m(101)) << bad;
        EXPECT_EQ(rig.r(360), 0) << bad;
        EXPECT_EQ(rig.r(484), 0) << bad;
    }
    Rig good;
    good.scan();
    EXPECT_FALSE(good.m(100));
}

// The PV of point i is TPSNS's TR + Sn + i, and PID starts at the scan its points have all been
// read (sn 4, zn 2: group 1 at 670 ms). The law is TSTC's: 60 × 4.095 + 60 × 0.17 × 2/60 × 4.095
// = 247 at E = 1 °C, on 0-4095.
TEST(FbTpctl, PidOnTpsnsReadingsOnceRead) {
    Rig rig(tpsns() + tpctl("sn: 4, zn: 2"));
    enable_sp_201_on_points_4_5(rig);
    rig.scan(67);  // …660 ms
    EXPECT_EQ(rig.r(450), 0);
    EXPECT_EQ(rig.r(484), 0);
    rig.scan();  // 670 ms: points 4-7 read
    EXPECT_EQ(rig.r(450), 247);
    EXPECT_EQ(rig.r(451), 247);
    EXPECT_EQ(rig.r(484), 0x0202);
}

// Point i's PV is taken from TR + Sn + i at each PID step, whoever wrote it: with Ts 1 s (R4005
// 0003h) PID steps at 670 and 1670 ms, and TPSNS rereads points 4-7 only at 2668 ms, so R5 set
// to 100 °C after the first step is point 1's PV at the second — its output (R451) goes to
// full scale while point 0's (R450, PV R4 still 200) only takes its integral step.
TEST(FbTpctl, PvIsTrPlusSnPlusIAtEachStep) {
    Rig rig(tpsns() + tpctl("sn: 4, zn: 2"));
    rig.set_r(4005, 0x0003);
    enable_sp_201_on_points_4_5(rig);
    rig.scan(68);  // 670 ms: points 4-7 read, the first step
    ASSERT_EQ(rig.r(484), 0x0201);
    const std::uint16_t first = rig.r(450);
    EXPECT_EQ(rig.r(451), first);
    rig.set_r(5, 100);
    rig.scan(99);  // …1660 ms: no step
    EXPECT_EQ(rig.r(450), first);
    EXPECT_EQ(rig.r(451), first);
    rig.scan();  // 1670 ms: the second step
    EXPECT_EQ(rig.r(450), first + 1);
    EXPECT_EQ(rig.r(451), 4095);
    EXPECT_EQ(rig.r(5), 100) << "not reread before 2668 ms";
}

// R4005 as TSTC's: low byte Ts, high byte PWM, 0 → 2 s, 1 → 4 s, 2 → 8 s, ≥ 3 → 1 s, read when EN
// rises; WR+4 shows them (0 while PID does not run).
TEST(FbTpctl, R4005TimingCodesInWr4) {
    struct Case {
        int r4005;
        int wr4;
    };
    for (const Case& c : {Case{0x0000, 0x0202}, Case{0x0001, 0x0204}, Case{0x0103, 0x0401},
                          Case{0x0300, 0x0102}, Case{0x0202, 0x0808}}) {
        Rig rig;
        rig.set_r(4005, c.r4005);
        rig.start(200);
        EXPECT_EQ(rig.r(484), c.wr4) << c.r4005;
        rig.set_r(4005, 0x0000);
        rig.scan(10);
        EXPECT_EQ(rig.r(484), c.wr4) << "a change while EN = 1 waits";
    }
}

// WR+0/WR+1 in zone (points Sn+0…15 / Sn+16…23, B0–B7); WR+2/WR+3 over-temperature or heater
// open; WR+5/WR+6 the over-temperature bits alone; WR+7/WR+8 heater open alone. ALM = a point
// out of zone or a warning.
TEST(FbTpctl, WorkingWords) {
    Rig rig;
    rig.start(200);
    EXPECT_EQ(rig.r(480), 0xFFFF);
    EXPECT_EQ(rig.r(481), 0x00FF);
    EXPECT_FALSE(rig.m(101));
    rig.set_r(323, 100);  // point 23 out of zone
    rig.scan();
    EXPECT_EQ(rig.r(481), 0x007F);
    EXPECT_TRUE(rig.m(101));
    rig.set_r(323, 200);
    rig.set_r(4008, 200);
    rig.scan(10);
    EXPECT_EQ(rig.r(482), 0xFFFF);
    EXPECT_EQ(rig.r(483), 0x00FF);
    EXPECT_EQ(rig.r(485), 0xFFFF);
    EXPECT_EQ(rig.r(486), 0x00FF);
    EXPECT_EQ(rig.r(487), 0);
    EXPECT_EQ(rig.r(488), 0);
    EXPECT_TRUE(rig.m(101));
}

// FB manual FUN86: R4013 B0–B7 = points 16–23 ("Bit7=1 means that 24th point"); bit 0: output
// OFF, OR 0, and no ALM for being out of zone. B8–B15 mean nothing.
TEST(FbTpctl, R4013BitsZeroToSeven) {
    Rig rig;
    rig.start(250);
    EXPECT_EQ(rig.r(473), 4095);
    rig.set_r(4013, 0x00FF);
    rig.scan();
    EXPECT_EQ(rig.r(473), 4095);
    rig.set_r(4013, 0xFF7F);
    rig.scan();
    EXPECT_EQ(rig.r(473), 0);
    EXPECT_FALSE(rig.y(30 + 23));
    rig.set_block(300, 200, 23);
    rig.scan();
    EXPECT_EQ(rig.r(481), 0x007F);
    EXPECT_FALSE(rig.m(101));
}

// R4006 is taken within 80–100: OR at 75 % never counts as large power with R4006 = 50 (taken
// as 80), and OR 4095 counts with R4006 = 120 (taken as 100).
TEST(FbTpctl, R4006ClampedTo80To100) {
    Rig low(tpsns() + tpctl("sn: 0, zn: 1"));
    low.set_r(4006, 50);
    low.set_r(4007, 300);
    low.start(210, 75, 0);  // P = 75 × 10 × 4.095 = 3071, 75 %
    EXPECT_EQ(low.r(450), 3071);
    low.scan(31000);
    EXPECT_EQ(low.r(487), 0);

    Rig high(tpsns() + tpctl("sn: 0, zn: 1"));
    high.set_r(4006, 120);
    high.set_r(4007, 300);
    high.start(300);
    EXPECT_EQ(high.r(450), 4095);
    high.scan(30000);
    EXPECT_EQ(high.r(487), 0x0001);
    EXPECT_EQ(high.r(482), 0x0001);
}

// R4007 is at least 300 s: with R4007 = 10 the heater-open warning comes after 300 s of full
// output out of zone, not 10 s.
TEST(FbTpctl, R4007AtLeast300Seconds) {
    Rig rig(tpsns() + tpctl("sn: 0, zn: 1"));
    rig.set_r(4007, 10);
    rig.start(300);   // point 0 is read at 340 ms (scan 34): full output from there
    rig.scan(29833);  // …scan 30033
    EXPECT_EQ(rig.r(487), 0);
    rig.scan(1);  // scan 30034: 300 s
    EXPECT_EQ(rig.r(487), 0x0001);
    EXPECT_EQ(rig.r(482), 0x0001);
}

// R4008 is at least 50 (whole degrees): with R4008 = 10 a point at 40 °C is not over
// temperature and one at 60 °C is.
TEST(FbTpctl, R4008AtLeast50) {
    Rig rig(tpsns() + tpctl("sn: 0, zn: 2"), "[FB-4AK24]",
            "  defaults: {k: 0, ambient: 40}\n  channels:\n    1: {ambient: 60}\n");
    rig.set_r(4008, 10);
    rig.start(50);
    rig.scan(20);
    EXPECT_EQ(rig.r(485), 0x0002);
}

// docs/profile-fb.md, "FUN73 TSTC", broken point: a broken sensor's reading (991 for K on 0~10 V)
// is a temperature and counts for over-temperature once it has stood ≥ R4008 for 10 consecutive
// scans — WR+5 and WR+2 bit 0, and ALM — while the point's output is OFF and OR 0. With R4008
// above the reading there is no over-temperature.
TEST(FbTpctl, BrokenPointCountsForOverTemperature) {
    for (const int r4008 : {350, 1000}) {
        Rig rig(tpsns() + tpctl("sn: 0, zn: 2"));
        rig.set_r(4008, r4008);
        rig.start(200);  // in zone: no warning, ALM OFF
        EXPECT_FALSE(rig.m(101));
        EXPECT_EQ(rig.r(485), 0);
        plant::Faults f;
        f.sensor_broken = true;
        rig.plc.plant().set_faults(0, f);
        rig.set_block(300, 250, 2);  // now full output for a sound point
        rig.scan(34);                // 2340 ms: point 0 read again, broken
        EXPECT_EQ(rig.r(0), 991);
        EXPECT_EQ(rig.r(450), 0);
        EXPECT_FALSE(rig.y(30));
        EXPECT_EQ(rig.r(451), 4095) << "point 1 is sound";
        EXPECT_EQ(rig.r(485), 0) << "not yet 10 scans";
        rig.scan(10);
        const int over = r4008 == 350 ? 0x0001 : 0;
        EXPECT_EQ(rig.r(485), over) << r4008;
        EXPECT_EQ(rig.r(482), over) << r4008;
        EXPECT_EQ(rig.r(450), 0) << r4008;
        EXPECT_FALSE(rig.y(30)) << r4008;
        EXPECT_TRUE(rig.m(101)) << r4008;  // out of zone (SP 250) either way
    }
}

// EN off: Yn OFF, OR 0, WR+0…WR+8 0, ALM OFF.
TEST(FbTpctl, EnOff) {
    Rig rig;
    rig.start(250);
    EXPECT_TRUE(rig.m(101));
    rig.set_m(0, false);
    rig.scan();
    for (std::uint32_t w = 0; w < tpctl::kWorkingWords; ++w) EXPECT_EQ(rig.r(480 + w), 0) << w;
    for (std::uint32_t i = 0; i < 24; ++i) EXPECT_EQ(rig.r(450 + i), 0) << i;
    for (std::uint32_t y = 30; y < 54; ++y) EXPECT_FALSE(rig.y(y)) << y;
    EXPECT_FALSE(rig.m(101));
    EXPECT_EQ(rig.r(0), 200);
}

// FB manual FUN86: "the FUN85 instruction … must be enabled, then, can the FUN86 start working":
// TPSNS's EN off turns the outputs OFF and OR 0; back on, PID restarts once the points are read.
TEST(FbTpctl, TpsnsEnOffStopsTheLoop) {
    Rig rig;
    rig.start(250);
    EXPECT_EQ(rig.r(450), 4095);
    rig.set_m(1, false);
    rig.scan();
    EXPECT_EQ(rig.r(450), 0);
    EXPECT_FALSE(rig.y(30));
    EXPECT_EQ(rig.r(484), 0);
    EXPECT_FALSE(rig.m(101));
    rig.set_m(1, true);
    rig.scan(200);
    EXPECT_EQ(rig.r(450), 0);
    rig.scan();
    EXPECT_EQ(rig.r(450), 4095);
}

// The plant: Y(yn + i) heats channel sn + i (TPSNS point sn + i), as TSTC's outputs do.
TEST(FbTpctl, PwmOutputsDriveTheirChannels) {
    Rig rig(tpsns() + tpctl("sn: 2, zn: 2"), "[FB-4AK24]", "  defaults: {ambient: 25}\n");
    rig.set_block(300, 150, 2);
    rig.set_block(330, 5, 2);
    rig.set_m(0, true);
    rig.set_m(1, true);
    rig.scan(6000);
    EXPECT_GT(rig.plc.plant().true_temperature(2), 60.0);
    EXPECT_GT(rig.plc.plant().true_temperature(3), 60.0);
    EXPECT_NEAR(rig.plc.plant().true_temperature(1), 25.0, 1.0);
    EXPECT_NEAR(rig.plc.plant().true_temperature(4), 25.0, 1.0);
}

// Load checks: md (the FBs' operand); no TPSNS; Sn + Zn past the installed module's points;
// two TPCTLs on one point.
TEST(FbTpctl, LoadChecks) {
    using testing::config_failure;
    using testing::expect_config_error;
    std::string p = tpctl();
    p.replace(p.find("hc: 1"), 5, "hc: 1, md: 1");
    expect_config_error(config_failure([&] { Rig rig(tpsns() + p); }), "fb.yaml", 9, 32,
                        "has no Md");
    expect_config_error(config_failure([] { Rig rig(tpctl(), "[]"); }), "fb.yaml", 8, 5,
                        "TPCTL needs a TPSNS");
    expect_config_error(
        config_failure([] { Rig rig(tpsns() + tpctl("sn: 8, zn: 8"), "[FB-4AK12]"); }), "fb.yaml",
        9, 48, "the FB-4AK12 at fb.yaml:4:13 has points 0-11");
    EXPECT_NO_THROW(Rig(tpsns() + tpctl("sn: 4, zn: 8"), "[FB-4AK12]"));
    // Out of the instruction's own range it is ERR at run time, not a config error.
    EXPECT_NO_THROW(Rig(tpsns() + tpctl("sn: 8, zn: 20"), "[FB-4AK12]"));
    const std::string second = elsewhere(tpctl("sn: 10, zn: 4"));
    expect_config_error(config_failure([&] { Rig rig(tpsns() + tpctl("sn: 0, zn: 12") + second); }),
                        "fb.yaml", 10, 41,
                        "point 10 is already controlled by the TPCTL at fb.yaml:9:5");
}

// Load checks, the operand areas (docs/profile-fb.md, "FUN86 TPCTL"): SV…WR lie in R0–R3839,
// R5000–R8071 or D0–D3071 (the FB's D, not the FBs' D0–D3999) — `sv: R3840` and a WR reaching
// past D3071 (D3064, nine words) are refused at the operand; the last blocks that fit load.
TEST(FbTpctl, LoadChecksOperandAreas) {
    using testing::config_failure;
    using testing::expect_config_error;
    const std::string areas = "R0-R3839, R5000-R8071 or D0-D3071";
    expect_config_error(
        config_failure([] { Rig rig(tpsns() + with(tpctl(), "sv: R300", "sv: R3840")); }),
        "fb.yaml", 9, 56, areas);
    expect_config_error(
        config_failure([] { Rig rig(tpsns() + with(tpctl(), "sv: R300", "sv: R3820")); }),
        "fb.yaml", 9, 56, areas);
    expect_config_error(
        config_failure([] { Rig rig(tpsns() + with(tpctl(), "wr: R480", "wr: D3064")); }),
        "fb.yaml", 9, 116, "expected 9 word(s) in R, D, got 'D3064'");
    EXPECT_NO_THROW(Rig(tpsns() + with(tpctl(), "sv: R300", "sv: R3816")));
    EXPECT_NO_THROW(Rig(tpsns() + with(tpctl(), "sv: R300", "sv: R5000")));
    EXPECT_NO_THROW(Rig(tpsns() + with(tpctl(), "wr: R480", "wr: D3063")));
}

// Load checks, what it writes (docs/profile-fb.md, "FUN86 TPCTL"): WR, OR, PR/IR/DR (the
// first execution's gains), Yn, ERR and ALM may not overlap a device the TPSNS writes — f19's
// PR on TR, OR on TPSNS's WR, WR on TR, f26's Yn on TPSNS's ERR, f25's ERR on TPSNS's ERR —
// refused at the TPCTL's operand, naming the TPSNS. ERR is written even with Sn/Zn out of
// range, so it is checked then too.
TEST(FbTpctl, LoadChecksWritesOverlappingTpsnsDevices) {
    using testing::config_failure;
    using testing::expect_config_error;
    const std::string same = "(two instructions may not write the same devices)";
    struct Case {
        std::string program;
        int col;
        std::string needle;
    };
    const std::string tpsns_err =
        "  - TPSNS: {en: M1, tp: 0, pl: 0, tr: R0, wr: R250, err: M100}\n";
    for (const Case& c : {
             Case{tpsns() + with(tpctl(), "pr: R360", "pr: R0"), 76,
                  "R0-R23 overlaps R0-R23 of the TPSNS at fb.yaml:8:5 " + same},
             Case{tpsns() + with(tpctl(), "or: R450", "or: R250"), 106,
                  "R250-R273 overlaps R250-R253 of the TPSNS at fb.yaml:8:5 " + same},
             Case{tpsns() + with(tpctl(), "wr: R480", "wr: R20"), 116,
                  "R20-R28 overlaps R0-R23 of the TPSNS at fb.yaml:8:5 " + same},
             Case{with(tpsns_err, "M100", "Y30") + tpctl(), 32,
                  "Y30-Y53 overlaps Y30 of the TPSNS at fb.yaml:8:5 " + same},
             Case{tpsns_err + tpctl(), 127, "M100 overlaps M100 of the TPSNS at fb.yaml:8:5"},
             Case{tpsns_err + tpctl("sn: 20, zn: 5"), 127, "of the TPSNS at fb.yaml:8:5"},
         }) {
        expect_config_error(config_failure([&] { Rig rig(c.program); }), "fb.yaml", 9, c.col,
                            c.needle);
    }
}

// Load checks, what it reads: SV and OS are settings it only reads; refused where the TPSNS
// writes (f27: SV on TR, so the readings would overwrite the setpoints), naming it. A MOV may
// write them: only the temperature instructions' devices are checked.
TEST(FbTpctl, LoadChecksSettingsTheTpsnsWrites) {
    using testing::config_failure;
    using testing::expect_config_error;
    const std::string why = "(it writes them, and this instruction reads them as settings)";
    expect_config_error(
        config_failure([] { Rig rig(tpsns() + with(tpctl(), "sv: R300", "sv: R0")); }), "fb.yaml",
        9, 56, "R0-R23 overlaps R0-R23 of the TPSNS at fb.yaml:8:5 " + why);
    expect_config_error(
        config_failure([] { Rig rig(tpsns() + with(tpctl(), "os: R330", "os: R10")); }), "fb.yaml",
        9, 66, "R10-R33 overlaps R0-R23 of the TPSNS at fb.yaml:8:5 " + why);
    const std::string mov = "  - MOV: {en: 1, s: 150, d: R300}\n";
    EXPECT_NO_THROW(Rig(tpsns() + mov + tpctl()));
    EXPECT_NO_THROW(Rig(tpsns() + tpctl() + mov));
}

// Load checks within the instruction: a block it writes may hold none of its other operands (SV
// in its own OR, PR in its own WR, ALM on its ERR); SV and OS, both only read, may be one block.
TEST(FbTpctl, LoadChecksItsOwnBlocks) {
    using testing::config_failure;
    using testing::expect_config_error;
    expect_config_error(
        config_failure([] { Rig rig(tpsns() + with(tpctl(), "sv: R300", "sv: R455")); }), "fb.yaml",
        9, 56, "R455-R478 overlaps its own or R450-R473");
    expect_config_error(
        config_failure([] { Rig rig(tpsns() + with(tpctl(), "pr: R360", "pr: R470")); }), "fb.yaml",
        9, 76, "R470-R493 overlaps its own wr R480-R488");
    expect_config_error(
        config_failure([] { Rig rig(tpsns() + with(tpctl(), "alm: M101", "alm: M100")); }),
        "fb.yaml", 9, 138, "M100 overlaps its own err M100");
    EXPECT_NO_THROW(Rig(tpsns() + with(tpctl(), "os: R330", "os: R300")));
}

// Load checks between TPCTLs: two may share SV and OS (settings both only read), but the later
// one's SV may not lie in the earlier one's PR (its first execution writes the gains there), nor
// its PR (with its own SV elsewhere) in the earlier one's SV; refused at the later entry, naming
// the earlier.
TEST(FbTpctl, LoadChecksBetweenTpctls) {
    using testing::config_failure;
    using testing::expect_config_error;
    const std::string second = elsewhere(tpctl("sn: 12, zn: 12"));
    const std::string first = tpsns() + tpctl("sn: 0, zn: 12");
    EXPECT_NO_THROW(Rig(first + second));
    expect_config_error(
        config_failure([&] { Rig rig(first + with(second, "sv: R300", "sv: R360")); }), "fb.yaml",
        10, 57,
        "R360-R371 overlaps R360-R371 of the TPCTL at fb.yaml:9:5 (it writes them, "
        "and this instruction reads them as settings)");
    expect_config_error(
        config_failure([&] {
            Rig rig(first + with(with(second, "sv: R300", "sv: R600"), "pr: R500", "pr: R300"));
        }),
        "fb.yaml", 10, 77,
        "R300-R311 overlaps R300-R311 of the TPCTL at fb.yaml:9:5 (it reads them "
        "as settings, and this instruction writes them)");
}

// Program order is not a rule (the manual's "FUN85 … must be enabled" is about EN): a TPCTL
// ahead of its TPSNS loads and runs on the readings of the scan before — PID starts one scan
// later than with the TPSNS first (scan 202, not 201), and TPSNS's EN falling stops it one scan
// later.
TEST(FbTpctl, BeforeTpsnsRunsAScanLate) {
    Rig rig(tpctl() + tpsns());
    rig.set_block(300, 250);
    rig.set_block(330, 5);
    rig.set_m(0, true);
    rig.set_m(1, true);
    rig.scan(201);
    EXPECT_EQ(rig.r(450), 0);
    rig.scan();
    EXPECT_EQ(rig.r(450), 4095);
    EXPECT_EQ(rig.r(484), 0x0202);
    rig.set_m(1, false);
    rig.scan();
    EXPECT_EQ(rig.r(450), 4095);
    rig.scan();
    EXPECT_EQ(rig.r(450), 0);
    EXPECT_FALSE(rig.y(30));
}

}  // namespace
}  // namespace plcemu::profiles::fb
