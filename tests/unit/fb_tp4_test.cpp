// FUN72 TP4 (FB manual FUN72/FUN73; docs/profile-fb.md, "FUN72 TP4"): the measuring cycle over
// the multiplexing relays (R4014 ms a point, Ym+2k/Ym+2k+1 for point k), AR, R3968+p and the
// reading, WR+0 broken bits, WR+1 read-once bits, ALM, the R4010 installed bits, R4015
// averaging, RTD points with R4020/R4021 compensation and the plant's lead resistance, ERR for
// Tp/Pl/Sm out of range, EN falling, and the load checks.

#include <gtest/gtest.h>

#include <string>

#include "plcemu/config/config.hpp"
#include "plcemu/daemon/plc.hpp"
#include "plcemu/plant/plant.hpp"
#include "support/plc_rig.hpp"
#include "support/config_errors.hpp"

namespace plcemu::profiles::fb {
namespace {

using image::Area;

constexpr const char* kTp4 =
    "  - TP4: {en: M3, tp: 0, pl: 0, sm: 0, ym: Y16, ar: R3842, tr: R0, wr: R220, err: M110, "
    "alm: M111}\n";

// An FB PLC whose plant channels sit at their ambient (k 0).
struct Rig : testing::PlcRig {
    explicit Rig(const std::string& program = kTp4,
                 const std::string& plant = "    0: {ambient: 200}\n")
        : PlcRig("profile: fb\nscan_ms: 10\nplant:\n  defaults: {k: 0}\n  channels:\n" + plant +
                     "program:\n" + program,
                 "fb.yaml") {}
    int sr(std::uint32_t i) { return static_cast<std::int16_t>(r(i)); }
    /// Writes R`reg` = `v`, runs one round of 4 × 500 ms and returns R0, the point 0 reading.
    int after(std::uint32_t reg, int v) {
        set_r(reg, v);
        scan(200);
        return sr(0);
    }
    unsigned relays() {
        unsigned bits = 0;
        for (std::uint32_t i = 0; i < 8; ++i) bits |= y(16 + i) ? 1u << i : 0u;
        return bits;
    }
    void set_ambient(int channel, double c) {
        auto p = plc.plant().params(channel);
        p.ambient_c = c;
        plc.plant().set_params(channel, p);
        plc.plant().set_temperature(channel, c);
    }
    /// EN on and a first round measured, then channel `channel`'s sensor broken for a round.
    void break_after_first_round(int channel) {
        set_m(3, true);
        scan(201);
        sensor_broken(channel, true);
        scan(200);
    }
};

// "当执行控制 EN=1 时，本指令执行多任务温度量测"; R4014 ms between points ("500 × 4 = 2000mS").
TEST(FbTp4, R4014MeasuringCycleAndRelays) {
    Rig rig;
    rig.set_m(3, true);
    rig.scan(50);                    // scans 0–49: point 0 selected
    EXPECT_EQ(rig.relays(), 0x03u);  // Y16, Y17
    EXPECT_EQ(rig.r(3968), 0);       // not sampled yet
    EXPECT_EQ(rig.r(3842), 826);     // AR shows the selected point
    rig.scan();                      // scan 50 = 500 ms: sample, select point 1
    EXPECT_EQ(rig.r(3968), 826);
    EXPECT_EQ(rig.r(0), 200);
    EXPECT_EQ(rig.relays(), 0x0Cu);  // Y18, Y19
    EXPECT_EQ(rig.r(222), 1);        // WR+2: point 1 being measured
    rig.scan();
    EXPECT_EQ(rig.r(3842), 103);    // point 1: channel 1 at the default 25 °C
    rig.scan(149);                  // points 1, 2, 3 at scans 100, 150, 200
    EXPECT_EQ(rig.r(221), 0x000F);  // WR+1: all four read once
    EXPECT_EQ(rig.r(220), 0);
    EXPECT_FALSE(rig.m(111));
    EXPECT_FALSE(rig.m(110));
    EXPECT_EQ(rig.relays(), 0x03u);  // back to point 0
    // R4014 = 0: one point a scan.
    rig.set_r(4014, 0);
    rig.scan(50);  // the pending 500 ms first
    rig.scan(1);
    const std::uint16_t at = rig.r(222);
    rig.scan(1);
    EXPECT_EQ(rig.r(222), (at + 1) % 4);
}

// R4016 changes the reading, never raw; R4009 = 1 gives °F.
TEST(FbTp4, R4016CalibratesTheReadingAndR4009Fahrenheit) {
    Rig rig;
    rig.set_m(3, true);
    rig.scan(51);
    EXPECT_EQ(rig.after(4016, 258), 208);
    EXPECT_EQ(rig.r(3968), 826);
    rig.set_r(4016, 248);
    EXPECT_EQ(rig.after(4009, 1), 392);
}

// R4010/R4011 and the broken-line rule: WR+0 bit k, ALM, the broken value.
TEST(FbTp4, BrokenThermocoupleAndInstalledBits) {
    Rig rig;
    rig.break_after_first_round(0);
    EXPECT_EQ(rig.r(3968), 4095);
    EXPECT_EQ(rig.r(0), 991);
    EXPECT_EQ(rig.r(220) & 1u, 1u);
    EXPECT_TRUE(rig.m(111));
    rig.set_r(4010, 0xFFFE);  // not installed: no check, reading 0
    rig.scan(200);
    EXPECT_EQ(rig.r(0), 0);
    EXPECT_EQ(rig.r(220) & 1u, 0u);
    EXPECT_FALSE(rig.m(111));
    EXPECT_EQ(rig.r(3968), 4095);  // raw is still written
    rig.set_r(4010, 0xFFFF);
    rig.sensor_broken(0, false);
    rig.scan(200);
    EXPECT_EQ(rig.r(0), 200);
    EXPECT_FALSE(rig.m(111));
}

// R4015 = 2: a moving average of the last 4 raws, fewer while fewer exist; a broken sample
// empties it.
TEST(FbTp4, R4015MovingAverage) {
    Rig rig;
    rig.set_r(4015, 2);
    rig.set_m(3, true);
    rig.scan(51);
    EXPECT_EQ(rig.r(0), 200);  // one sample
    rig.set_ambient(0, 300.0);
    rig.scan(200);  // samples 826, 1239
    EXPECT_EQ(rig.r(3968), 1239);
    EXPECT_EQ(rig.r(0), (826 + 1239) * 248 / (1024 * 2));
    rig.scan(200);
    rig.scan(200);
    rig.scan(200);  // 1239 × 4
    EXPECT_EQ(rig.r(0), 300);
    rig.set_r(4015, 0);
    rig.set_ambient(0, 100.0);
    rig.scan(200);
    EXPECT_EQ(rig.r(0), rig.r(3968) * 248 / 1024);
}

// RTD (Tp 2, Pt100): "最后再将工程单位值转换后存入 R3968"; R4020/R4021 compensation against the
// plant's lead resistance; R4022; broken RTD 32767.
TEST(FbTp4, RtdPointsAndLineResistance) {
    Rig rig(
        "  - TP4: {en: M3, tp: 2, pl: 2, sm: 0, ym: Y16, ar: R3842, tr: R0, wr: R220, "
        "alm: M111}\n",
        "    0: {ambient: 50}\n");
    rig.set_m(3, true);
    rig.scan(51);
    EXPECT_EQ(rig.r(0), 500);
    EXPECT_EQ(rig.r(3968), 2081);
    rig.set_r(4021, 5000);
    EXPECT_EQ(rig.after(5000, 10), 474);
    rig.set_r(5000, 0);
    auto p = rig.plc.plant().params(0);
    p.lead_ohm = 1.5;
    rig.plc.plant().set_params(0, p);
    rig.scan(200);
    EXPECT_EQ(rig.r(0), 539);
    EXPECT_EQ(rig.after(5000, 15), 500);
    rig.sensor_broken(0, true);
    rig.scan(200);
    EXPECT_EQ(rig.r(0), 32767);
    EXPECT_EQ(rig.r(3968), 4095);
    EXPECT_TRUE(rig.m(111));
}

// Tp, Pl or Sm out of range: not executed, ERR ON at every scan, whatever EN.
TEST(FbTp4, ErrForOperandsOutOfRange) {
    for (const char* bad : {"tp: 6, pl: 0, sm: 0", "tp: 0, pl: 4, sm: 0", "tp: 0, pl: 0, sm: 2",
                            "tp: 0, pl: 0, sm: 32", "tp: -1, pl: 0, sm: 0"}) {
        Rig rig(std::string("  - TP4: {en: M3, ") + bad +
                ", ym: Y16, ar: R3842, tr: R0, wr: R220, err: M110, alm: M111}\n");
        rig.scan(100);
        EXPECT_TRUE(rig.m(110)) << bad;
        rig.set_m(3, true);
        rig.scan(300);
        EXPECT_TRUE(rig.m(110)) << bad;
        EXPECT_EQ(rig.relays(), 0u) << bad;
        EXPECT_EQ(rig.r(3968), 0) << bad;
        EXPECT_EQ(rig.r(3842), 0) << bad;
    }
}

// EN falls: relays OFF, WR cleared, ALM OFF; TR and R3968+p keep their values.
TEST(FbTp4, EnFalls) {
    Rig rig;
    rig.break_after_first_round(1);
    EXPECT_TRUE(rig.m(111));
    rig.set_m(3, false);
    rig.scan();
    EXPECT_EQ(rig.relays(), 0u);
    EXPECT_EQ(rig.r(220), 0);
    EXPECT_EQ(rig.r(221), 0);
    EXPECT_FALSE(rig.m(111));
    EXPECT_EQ(rig.r(0), 200);
    EXPECT_EQ(rig.r(3968), 826);
    // Rising again starts at point 0 with nothing read.
    rig.set_m(3, true);
    rig.scan();
    EXPECT_EQ(rig.relays(), 0x03u);
    EXPECT_EQ(rig.r(221), 0);
}

// Load checks (docs/profile-fb.md, "FUN72 TP4"), each at the operand with file:line:col.
TEST(FbTp4, LoadChecks) {
    const std::string a = "  - TP4: {tp: 0, pl: 0, sm: 0, ym: Y16, ar: R3842, tr: R0, wr: R220}\n";
    struct Case {
        std::string program;
        int line, col;
        const char* needle;
    };
    const Case cases[] = {
        {a + "  - TP4: {tp: 0, pl: 0, sm: 0, ym: Y24, ar: R3845, tr: R4, wr: R230}\n", 9, 29,
         "points 0-3 are already measured by the TP4 at fb.yaml:8:5"},
        {a + "  - TP4: {tp: 0, pl: 0, sm: 4, ym: Y20, ar: R3845, tr: R4, wr: R230}\n", 9, 36,
         "Y20-Y27 overlaps Y16-Y23 of the TP4 at fb.yaml:8:5"},
        {a + "  - TP4: {tp: 0, pl: 0, sm: 4, ym: Y24, ar: R3845, tr: R4, wr: R223}\n", 9, 64,
         "R223-R230 overlaps R220-R227"},
        {"  - TP4: {tp: 0, pl: 0, sm: 0, ym: Y16, ar: R3842, tr: R0, wr: R2}\n", 8, 56,
         "R0-R3 overlaps its own wr R2-R9"},
        {"  - TP4: {tp: 0, pl: 0, sm: 0, ym: Y16, ar: R100, tr: R0, wr: R220}\n", 8, 45,
         "expected an IR register R3840-R3903"},
        {"  - TP4: {tp: 0, pl: 0, sm: 0, ym: Y16, ar: R3842, tr: R3900, wr: R220}\n", 8, 56,
         "R0-R3839, R5000-R8071 or D0-D3071"},
        {"  - TP4: {tp: 0, pl: 0, sm: 0, ym: Y250, ar: R3842, tr: R0, wr: R220}\n", 8, 36,
         "8 consecutive"},
    };
    for (const Case& c : cases) {
        SCOPED_TRACE(c.program);
        testing::expect_config_error(testing::config_failure([&] { Rig rig(c.program); }),
                                     "fb.yaml", c.line, c.col, c.needle);
    }
}

// Load checks, its bits (docs/profile-fb.md, "Shared devices"): ERR and ALM are written, so
// neither may be another instruction's written bit (refused at the later entry, naming the
// earlier) nor another of its own operands. ERR is written even with Tp/Pl/Sm out of range, and
// ALM only with them valid, so an invalid TP4's ALM is not checked.
TEST(FbTp4, LoadChecksErrAndAlm) {
    const std::string second =
        "  - TP4: {en: M3, tp: 0, pl: 0, sm: 4, ym: Y24, ar: R3845, tr: R4, wr: R230, err: M112, "
        "alm: M113}\n";
    const auto with = [](std::string text, const std::string& from, const std::string& to) {
        return text.replace(text.find(from), from.size(), to);
    };
    const std::string same =
        " of the TP4 at fb.yaml:8:5 (two instructions may not write the same devices)";
    struct Case {
        std::string program;
        int line, col;
        std::string needle;
    };
    const Case cases[] = {
        {kTp4 + with(second, "err: M112", "err: M110"), 9, 83, "M110 overlaps M110" + same},
        {kTp4 + with(second, "alm: M113", "alm: M110"), 9, 94, "M110 overlaps M110" + same},
        {kTp4 + with(with(second, "tp: 0", "tp: 9"), "err: M112", "err: M111"), 9, 83,
         "M111 overlaps M111" + same},
        {with(kTp4, "alm: M111", "alm: M110"), 8, 94, "M110 overlaps its own err M110"},
        {with(kTp4, "err: M110", "err: Y20"), 8, 83, "Y20 overlaps its own ym Y16-Y23"},
    };
    for (const Case& c : cases) {
        SCOPED_TRACE(c.program);
        testing::expect_config_error(testing::config_failure([&] { Rig rig(c.program); }),
                                     "fb.yaml", c.line, c.col, c.needle);
    }
    EXPECT_NO_THROW(Rig(kTp4 + second));
    EXPECT_NO_THROW(Rig(kTp4 + with(with(second, "tp: 0", "tp: 9"), "alm: M113", "alm: M111")));
}

// With temperature.modules the module at Sm must be the one Tp names.
TEST(FbTp4, TpMustMatchTheModuleOfTheChain) {
    const auto build = [](const std::string& modules, const std::string& tp4) {
        daemon::Plc plc(config::parse_config(
            "profile: fb\ntemperature: {modules: [" + modules + "]}\nprogram:\n" + tp4, "fb.yaml"));
    };
    EXPECT_NO_THROW(
        build("FB-2AK4, FB-2AJ4",
              "  - TP4: {tp: 1, pl: 0, sm: 4, ym: Y16, ar: R3842, tr: R0, wr: R220}\n"));
    testing::expect_config_error(
        testing::config_failure([&] {
            build("FB-2AK4, FB-2AJ4",
                  "  - TP4: {tp: 0, pl: 0, sm: 4, ym: Y16, ar: R3842, tr: R0, wr: R220}\n");
        }),
        "fb.yaml", 4, 15, "0 does not match the FB-2AJ4 at fb.yaml:2:34");
    testing::expect_config_error(
        testing::config_failure([&] {
            build("FB-2AK4",
                  "  - TP4: {tp: 0, pl: 0, sm: 4, ym: Y16, ar: R3842, tr: R0, wr: R220}\n");
        }),
        "fb.yaml", 4, 29, "temperature.modules lists 1");
}

}  // namespace
}  // namespace plcemu::profiles::fb
