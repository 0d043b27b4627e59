// FUN73 TSTC (FB manual FUN73; docs/profile-fb.md, "FUN73 TSTC"): ERR for Sh/Zh out of range or
// Sh < Sm, the first-execution defaults, PID only once every point has been read, the PID law on
// 0–4095 with the error scaled by 4095 / full scale, R4005's FB codes, the in-zone band, the
// R4008 over-temperature in whole degrees, broken points, R4012, EN = 0, and the load checks.

#include <gtest/gtest.h>

#include <string>

#include "plcemu/config/config.hpp"
#include "plcemu/daemon/plc.hpp"
#include "plcemu/plant/plant.hpp"
#include "profiles/fb/control_loop.hpp"
#include "profiles/fb/tstc.hpp"
#include "support/plc_rig.hpp"
#include "support/config_errors.hpp"

namespace plcemu::profiles::fb {
namespace {

using image::Area;

std::string tstc(const std::string& module = "tp: 0, pl: 0, sm: 0",
                 const std::string& points = "sh: 0, zh: 4") {
    return "  - TSTC: {en: M0, hc: 1, " + module + ", ym: Y16, ar: R3842, tr: R0, yh: Y48, " +
           points +
           ", sv: R100, os: R120, pr: R140, ir: R160, dr: R180, or: R300, wr: R200, err: M100, "
           "ao0: M101, ao1: M102}\n";
}

// `text` with its first `from` replaced by `to`.
std::string with(std::string text, const std::string& from, const std::string& to) {
    return text.replace(text.find(from), from.size(), to);
}

// `text`, a tstc() on module 4, with the devices it writes moved clear of tstc()'s (Ym Y24, AR
// R3845, TR R4, Yh Y60, PR…WR R420…R460, ERR/AO0/AO1 M110…M112) and its SV and OS kept.
std::string elsewhere(std::string text) {
    for (const auto& [from, to] : {std::pair<std::string, std::string>{"ym: Y16", "ym: Y24"},
                                   {"R3842", "R3845"},
                                   {"tr: R0", "tr: R4"},
                                   {"Y48", "Y60"},
                                   {"R140", "R420"},
                                   {"R160", "R430"},
                                   {"R180", "R440"},
                                   {"R300", "R450"},
                                   {"R200", "R460"},
                                   {"M100", "M110"},
                                   {"M101", "M111"},
                                   {"M102", "M112"}}) {
        text = with(text, from, to);
    }
    return text;
}

// An FB PLC whose plant channels 0–7 sit at 200 °C (k 0: the heaters change nothing).
struct Rig : testing::PlcRig {
    explicit Rig(const std::string& program = tstc())
        : PlcRig("profile: fb\nscan_ms: 10\nplant:\n  defaults: {k: 0, ambient: 200}\nprogram:\n" +
                     program,
                 "fb.yaml") {}
    void set_block(std::uint32_t at, int v, int n = 4) { PlcRig::set_block(at, v, n); }
    /// SP `sp`, offset 5, tuned gains Kc 60, Ti 17, Td 0; EN on and the four points read.
    void start(int sp) {
        set_block(100, sp);
        set_block(120, 5);
        set_block(140, 60);
        set_block(160, 17);
        set_block(180, 0);
        set_m(0, true);
        scan(202);  // point 3's sample falls on scan 200 (the 201st), and PID starts there
    }
};

// FB manual FUN73: "Sh or Zh out of range, or Sh < Sm": not executed, ERR ON, whatever EN.
TEST(FbTstc, ErrForShZhOutOfRangeOrShBelowSm) {
    for (const char* bad : {"sh: 0, zh: 0", "sh: 1, zh: 32", "sh: 32, zh: 1"}) {
        Rig rig(tstc("tp: 0, pl: 0, sm: 0", bad));
        rig.scan(10);
        EXPECT_TRUE(rig.m(100)) << bad;
        rig.set_m(0, true);
        rig.scan(300);
        EXPECT_TRUE(rig.m(100)) << bad;
        EXPECT_EQ(rig.r(3968), 0) << bad;
        EXPECT_EQ(rig.r(140), 0) << bad;
        EXPECT_FALSE(rig.y(16)) << bad;
    }
    Rig below(tstc("tp: 0, pl: 0, sm: 4", "sh: 0, zh: 4"));
    below.set_m(0, true);
    below.scan(300);
    EXPECT_TRUE(below.m(100));
    EXPECT_EQ(below.r(0), 0);
}

// FB manual FUN73, first execution: every point whose PR is 0 gets Kc by range (60/30/120/60;
// RTDs 120/60), Ti 17 and Td 100; a nonzero PR is kept.
TEST(FbTstc, FirstExecutionDefaults) {
    struct Case {
        const char* module;
        int kc;
    };
    for (const Case& c : {Case{"tp: 0, pl: 0, sm: 0", 60}, Case{"tp: 0, pl: 1, sm: 0", 30},
                          Case{"tp: 1, pl: 2, sm: 0", 120}, Case{"tp: 0, pl: 3, sm: 0", 60},
                          Case{"tp: 2, pl: 0, sm: 0", 120}, Case{"tp: 3, pl: 1, sm: 0", 60}}) {
        Rig rig(tstc(c.module));
        rig.set_r(141, 77);
        rig.scan(5);
        EXPECT_EQ(rig.r(140), 0) << "EN off: nothing given yet";
        rig.set_m(0, true);
        rig.scan();
        EXPECT_EQ(rig.r(140), c.kc) << c.module;
        EXPECT_EQ(rig.r(160), 17) << c.module;
        EXPECT_EQ(rig.r(180), 100) << c.module;
        EXPECT_EQ(rig.r(141), 77) << c.module;
        EXPECT_EQ(rig.r(161), 0) << c.module;
        EXPECT_EQ(rig.r(143), c.kc) << c.module;
    }
    EXPECT_EQ(control::default_kc(0, 0), 60);
}

// FB manual FUN73: "PID only really starts once every point has been measured"; a point no
// instruction measures is never read, so PID never starts.
TEST(FbTstc, PidWaitsUntilEveryPointIsRead) {
    Rig rig;
    rig.set_block(100, 250);
    rig.set_m(0, true);
    rig.scan(200);  // points 0-2 read, point 3 not yet
    EXPECT_EQ(rig.r(300), 0);
    EXPECT_EQ(rig.r(212), 0);
    rig.scan(2);
    EXPECT_EQ(rig.r(300), 4095);
    EXPECT_EQ(rig.r(212), 0x0202);

    Rig lone(tstc("tp: 0, pl: 0, sm: 0", "sh: 0, zh: 8"));
    lone.set_r(100, 250);
    lone.set_m(0, true);
    lone.scan(2000);
    EXPECT_EQ(lone.r(300), 0);
    EXPECT_FALSE(lone.y(48));
    EXPECT_EQ(lone.r(212), 0);
    // With a TP4 on points 4-7 reading into R4-R7 the loop starts.
    Rig paired(tstc("tp: 0, pl: 0, sm: 0", "sh: 0, zh: 8") +
               "  - TP4: {en: M0, tp: 0, pl: 0, sm: 4, ym: Y24, ar: R3845, tr: R4, wr: R220}\n");
    paired.set_r(100, 250);
    paired.set_m(0, true);
    paired.scan(202);
    EXPECT_EQ(paired.r(300), 4095);
    EXPECT_EQ(paired.r(4), 200);
}

// FB manual FUN73, the PID law: P = Kc·E·G with G = 4095 / full scale (1000 °C on 0~10 V),
// I += Kc·(Ti/100)·(Ts/60 s)·E·G per solution, OR 0–4095, one solution every Ts.
TEST(FbTstc, PidLawOnTheConverterFullScale) {
    Rig rig;
    rig.start(201);  // E = 1 °C
    // 60 × 4.095 + 60 × 0.17 × (2/60) × 4.095 = 245.7 + 1.39
    EXPECT_EQ(rig.r(300), 247);
    rig.scan(198);  // PID started at scan 200 (point 3's sample); scans 202-399
    EXPECT_EQ(rig.r(300), 247);
    rig.scan(1);  // scan 400, 2 s later: the integral again
    EXPECT_EQ(rig.r(300), 248);
    // The full scale behind G: 500 °C on 0~5 V, × 1.8 in °F.
    EXPECT_NEAR(control::full_scale(0, 1, false, false), 500.0, 1e-9);
    EXPECT_NEAR(control::full_scale(0, 0, true, false), 1800.0, 1e-9);
}

// FB manual FUN73, R4005: low byte Ts, high byte PWM, 0 → 2 s, 1 → 4 s, 2 → 8 s, ≥ 3 → 1 s, read
// when EN rises; WR+12 shows them.
TEST(FbTstc, R4005TimingCodes) {
    struct Case {
        int r4005;
        int wr12;
    };
    for (const Case& c : {Case{0x0000, 0x0202}, Case{0x0001, 0x0204}, Case{0x0103, 0x0401},
                          Case{0x0300, 0x0102}, Case{0x0202, 0x0808}, Case{0xFFFF, 0x0101}}) {
        Rig rig;
        rig.set_r(4005, c.r4005);
        rig.start(200);
        EXPECT_EQ(rig.r(212), c.wr12) << c.r4005;
        rig.set_r(4005, 0x0000);
        rig.scan(10);
        EXPECT_EQ(rig.r(212), c.wr12) << "a change while EN = 1 waits";
    }
}

// FB manual FUN73: SP − Os ≤ PV ≤ SP + Os is in zone (WR+8), else AO1; Os < 0 is never in zone;
// R4012 bit 0: no PID, output OFF, no AO1 for being out of zone.
TEST(FbTstc, ZoneAo1AndR4012) {
    Rig rig;
    rig.start(200);
    EXPECT_EQ(rig.r(208), 0x000F);
    EXPECT_FALSE(rig.m(102));
    rig.set_r(100, 100);
    rig.scan();
    EXPECT_EQ(rig.r(208), 0x000E);
    EXPECT_TRUE(rig.m(102));
    rig.set_r(100, 200);
    rig.set_r(121, -1);
    rig.scan();
    EXPECT_EQ(rig.r(208), 0x000D);
    rig.set_r(121, 5);
    rig.set_r(103, 300);  // point 3 far off, full output
    rig.scan(400);
    EXPECT_EQ(rig.r(303), 4095);
    rig.set_r(4012, 0xFFF7);
    rig.scan();
    EXPECT_EQ(rig.r(303), 0);
    EXPECT_FALSE(rig.y(51));
    EXPECT_EQ(rig.r(208), 0x0007);
    EXPECT_FALSE(rig.m(102));
}

// FB manual FUN73, over-temperature: the reading ≥ R4008 (whole degrees, at least 50) for 10
// consecutive scans sets WR+10 and WR+13 and AO1; it clears at the first scan below.
TEST(FbTstc, R4008OverTemperatureInWholeDegrees) {
    Rig rig;
    rig.set_r(4008, 200);
    rig.start(200);
    rig.scan(20);
    EXPECT_EQ(rig.r(210), 0x000F);
    EXPECT_EQ(rig.r(213), 0x000F);
    EXPECT_TRUE(rig.m(102));
    rig.set_r(4008, 201);
    rig.scan();
    EXPECT_EQ(rig.r(210), 0);
    EXPECT_FALSE(rig.m(102));
}

// FB manual FUN73: R4008 is whole degrees ("单位为度"); RTD readings are 0.1°, so they are compared
// with R4008 × 10: a Pt100 reading 146.6 °C (1466) is not over the default 350 °C.
TEST(FbTstc, R4008TimesTenForRtdReadings) {
    Rig rig(tstc("tp: 2, pl: 2, sm: 0"));
    rig.start(1466);
    rig.scan(20);
    EXPECT_EQ(rig.r(0), 1466);
    EXPECT_EQ(rig.r(213), 0);
    EXPECT_FALSE(rig.m(102));
    rig.set_r(4008, 146);
    rig.scan(10);
    EXPECT_EQ(rig.r(213), 0x000F);
    EXPECT_TRUE(rig.m(102));
    rig.set_r(4008, 147);
    rig.scan();
    EXPECT_EQ(rig.r(213), 0);
}

// Broken point: output OFF, out of zone, AO0 (WR+0); its reading (991 with K defaults) is a
// temperature and counts for over-temperature against R4008 350.
TEST(FbTstc, BrokenPointOutputOffAndOverTemperature) {
    Rig rig;
    rig.start(250);
    EXPECT_EQ(rig.r(301), 4095);
    rig.sensor_broken(1, true);
    rig.scan(220);
    EXPECT_EQ(rig.r(1), 991);
    EXPECT_EQ(rig.r(200), 0x0002);
    EXPECT_TRUE(rig.m(101));
    EXPECT_EQ(rig.r(301), 0);
    EXPECT_FALSE(rig.y(49));
    EXPECT_EQ(rig.r(213) & 0x2, 0x2);
}

// EN = 0: Ym, Yh OFF, OR 0, WR+0…WR+16 0, AO0/AO1 OFF; TR keeps its values.
TEST(FbTstc, EnOff) {
    Rig rig;
    rig.start(250);
    EXPECT_TRUE(rig.m(102));
    rig.set_m(0, false);
    rig.scan();
    for (std::uint32_t w = 0; w < tstc::kWorkingWords; ++w) EXPECT_EQ(rig.r(200 + w), 0) << w;
    for (std::uint32_t i = 0; i < 4; ++i) EXPECT_EQ(rig.r(300 + i), 0);
    for (std::uint32_t y = 16; y < 24; ++y) EXPECT_FALSE(rig.y(y));
    for (std::uint32_t y = 48; y < 52; ++y) EXPECT_FALSE(rig.y(y));
    EXPECT_FALSE(rig.m(101));
    EXPECT_FALSE(rig.m(102));
    EXPECT_EQ(rig.r(0), 200);
}

// Load checks: Ym overlapping Yh, OR overlapping WR; and FB manual FUN73's "TR must be contiguous,
// starting at the first point of modules of the same type": a TP4 measuring a point the TSTC
// controls must have its Tp and Pl and TR + (p - Sm), refused at whichever entry comes later.
TEST(FbTstc, LoadChecks) {
    const auto fails = [](const std::string& program, int line, const std::string& needle) {
        SCOPED_TRACE(program);
        const auto f = testing::config_failure([&] { Rig rig(program); });
        ASSERT_TRUE(f.thrown);
        EXPECT_NE(f.what.find(needle), std::string::npos) << f.what;
        EXPECT_EQ(f.what.rfind("fb.yaml:" + std::to_string(line) + ":", 0), 0u) << f.what;
    };
    std::string p = tstc();
    fails(p.replace(p.find("yh: Y48"), 7, "yh: Y20"), 6, "Y20-Y23 overlaps its own ym");
    p = tstc();
    fails(p.replace(p.find("or: R300"), 8, "or: R210"), 6, "overlaps its own wr");

    const std::string eight = tstc("tp: 0, pl: 0, sm: 0", "sh: 0, zh: 8");
    const auto tp4 = [](const std::string& tp_pl, const std::string& tr) {
        return "  - TP4: {en: M0, " + tp_pl + ", sm: 4, ym: Y24, ar: R3845, tr: " + tr +
               ", wr: R220}\n";
    };
    EXPECT_NO_THROW(Rig(eight + tp4("tp: 0, pl: 0", "R4")));
    EXPECT_NO_THROW(Rig(tp4("tp: 0, pl: 0", "R4") + eight));
    fails(eight + tp4("tp: 0, pl: 0", "R5"), 7, "must be at R4-R7");
    fails(eight + tp4("tp: 1, pl: 0", "R4"), 7, "same range and polarity");
    fails(eight + tp4("tp: 0, pl: 2", "R4"), 7, "same range and polarity");
    fails(tp4("tp: 0, pl: 0", "R40") + eight, 7, "TR must be contiguous");
    // A TP4 on points the TSTC does not control may read anywhere.
    EXPECT_NO_THROW(Rig(tstc() + tp4("tp: 1, pl: 0", "R40")));
    // One controller per point: a second TSTC on point 4 is refused at its sh.
    const std::string second = elsewhere(tstc("tp: 0, pl: 0, sm: 4", "sh: 4, zh: 4"));
    fails(eight + second, 7, "point 4 is already controlled by the TSTC at fb.yaml:6:5");
}

// A TP4 on module 4 (points 4–7, clear of tstc()'s devices), its TR at `tr`.
std::string tp4_at(const std::string& tr = "R4") {
    return "  - TP4: {en: M0, tp: 0, pl: 0, sm: 4, ym: Y24, ar: R3845, tr: " + tr +
           ", wr: R220, err: M110, alm: M111}\n";
}

const std::string kSame = "(two instructions may not write the same devices)";

// Load checks, its settings (docs/profile-fb.md, "Shared devices"): SV and OS are only read, so
// no other instruction may write them — a TP4's TR on them is refused at whichever entry comes
// later, naming the earlier — while a MOV may (that is how a program sets them).
TEST(FbTstc, LoadChecksSettingsAnotherInstructionWrites) {
    using testing::config_failure;
    using testing::expect_config_error;
    expect_config_error(config_failure([] { Rig rig(tstc() + tp4_at("R100")); }), "fb.yaml", 7, 64,
                        "R100-R103 overlaps R100-R103 of the TSTC at fb.yaml:6:5 (it reads them "
                        "as settings, and this instruction writes them)");
    expect_config_error(config_failure([] { Rig rig(tp4_at("R120") + tstc()); }), "fb.yaml", 7, 113,
                        "R120-R123 overlaps R120-R123 of the TP4 at fb.yaml:6:5 (it writes them, "
                        "and this instruction reads them as settings)");
    EXPECT_NO_THROW(Rig(tstc() + "  - MOV: {en: 1, s: 150, d: R100}\n"));
}

// Load checks, PR/IR/DR: its first execution writes the default gains there (FB manual FUN73),
// so they are written blocks — a TSTC's PR on a TP4's WR, and a TP4's TR on a TSTC's DR, are
// refused at the later entry.
TEST(FbTstc, LoadChecksGainsAreWritten) {
    using testing::config_failure;
    using testing::expect_config_error;
    expect_config_error(
        config_failure([] { Rig rig(with(tp4_at(), "wr: R220", "wr: R140") + tstc()); }), "fb.yaml",
        7, 123, "R140-R143 overlaps R140-R147 of the TP4 at fb.yaml:6:5 " + kSame);
    expect_config_error(config_failure([] { Rig rig(tstc() + tp4_at("R180")); }), "fb.yaml", 7, 64,
                        "R180-R183 overlaps R180-R183 of the TSTC at fb.yaml:6:5 " + kSame);
}

// Load checks, its bits: ERR, AO0 and AO1 are written, so none may be another instruction's
// written bit nor another of its own operands. ERR is written even with Sh/Zh out of range, AO0
// and AO1 only with them valid, so an invalid TSTC's AO1 is not checked.
TEST(FbTstc, LoadChecksErrAo0Ao1) {
    using testing::config_failure;
    using testing::expect_config_error;
    struct Case {
        std::string program;
        int line, col;
        std::string needle;
    };
    const std::string earlier = " of the TP4 at fb.yaml:6:5 " + kSame;
    const std::string bad = tstc("tp: 0, pl: 0, sm: 0", "sh: 0, zh: 40");
    for (const Case& c : {
             Case{tp4_at() + with(tstc(), "err: M100", "err: M110"), 7, 174,
                  "M110 overlaps M110" + earlier},
             Case{tp4_at() + with(tstc(), "ao0: M101", "ao0: M111"), 7, 185,
                  "M111 overlaps M111" + earlier},
             Case{tp4_at() + with(tstc(), "ao1: M102", "ao1: M110"), 7, 196,
                  "M110 overlaps M110" + earlier},
             Case{tp4_at() + with(bad, "err: M100", "err: M111"), 7, 175,
                  "M111 overlaps M111" + earlier},
             Case{with(tstc(), "ao1: M102", "ao1: M100"), 6, 196, "M100 overlaps its own err M100"},
             Case{with(tstc(), "ao0: M101", "ao0: Y48"), 6, 185, "Y48 overlaps its own yh Y48-Y51"},
         }) {
        SCOPED_TRACE(c.program);
        expect_config_error(config_failure([&] { Rig rig(c.program); }), "fb.yaml", c.line, c.col,
                            c.needle);
    }
    EXPECT_NO_THROW(Rig(tp4_at() + with(bad, "ao1: M102", "ao1: M110")));
}

// Load checks between settings: SV and OS may be one block, and two TSTCs may share SV and OS
// (settings both only read), but a block it writes may not hold its own SV (SV in its own PR),
// nor a later TSTC's SV lie in an earlier one's PR.
TEST(FbTstc, LoadChecksSharedSettings) {
    using testing::config_failure;
    using testing::expect_config_error;
    const std::string second = elsewhere(tstc("tp: 0, pl: 0, sm: 4", "sh: 4, zh: 4"));
    EXPECT_NO_THROW(Rig(with(tstc(), "os: R120", "os: R100")));
    EXPECT_NO_THROW(Rig(tstc() + second));
    expect_config_error(config_failure([] { Rig rig(with(tstc(), "sv: R100", "sv: R140")); }),
                        "fb.yaml", 6, 103, "R140-R143 overlaps its own pr R140-R143");
    expect_config_error(
        config_failure([&] { Rig rig(tstc() + with(second, "sv: R100", "sv: R140")); }), "fb.yaml",
        7, 103,
        "R140-R143 overlaps R140-R143 of the TSTC at fb.yaml:6:5 (it writes them, and this "
        "instruction reads them as settings)");
}

}  // namespace
}  // namespace plcemu::profiles::fb
