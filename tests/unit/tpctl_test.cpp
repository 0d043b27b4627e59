// FUN86 TPCTL (FBs manual §21.7; docs/profile-fbs.md, FUN86 TPCTL): every rule of the section on an
// image driven by a fake scan context in virtual time. Readings and the temperature execute code
// are set directly in the image, as the measurement subsystem would leave them.

#include <gtest/gtest.h>

#include <chrono>
#include <string>
#include <vector>

#include "profiles/fbs/tpctl.hpp"
#include "support/config_errors.hpp"
#include "plcemu/daemon/plc.hpp"
#include "support/profiles.hpp"
#include "plcemu/config/config.hpp"
#include "plcemu/engine/engine.hpp"
#include "profiles/fbs/special_registers.hpp"
#include "plcemu/image/image.hpp"
#include "plcemu/instructions/instructions.hpp"

namespace plcemu::profiles::fbs {
namespace {

using image::Area;
using namespace std::chrono_literals;
using engine::Duration;

// The program example of FBs manual §21.7, with H/C on M1 so tests can switch heating and cooling.
const char* kExample =
    "  - TPCTL: {en: M0, hc: M1, md: 0, yn: Y30, sn: 0, zn: 10, sv: R100, os: R110, pr: R120,\n"
    "            ir: R130, dr: R140, or: R200, wr: R300, err: M100, alm: M101}\n";

std::string config_text(const std::string& program) {
    return "profile: fbs\ntemperature: {table: R5000}\nprogram:\n" + program;
}

// Registers of the example's operands.
constexpr std::uint32_t kSv = 100, kOs = 110, kPr = 120, kIr = 130, kDr = 140, kOr = 200, kWr = 300,
                        kY = 30;

/// An image with the temperature table of default.yaml (readings R0…, measurement WR at D0),
/// the special-register defaults of FBs manual §21.7 and a program; scans in virtual time.
class Rig {
public:
    explicit Rig(const std::string& program = kExample, Duration dt = 10ms)
        : cfg_(config::parse_config(config_text(program), "tpctl_test.yaml")),
          img_(testing::fbs_layout()),
          prog_(daemon::build_program(cfg_)),
          dt_(dt) {
        namespace sp = profiles::fbs::special;
        r(sp::kPidTiming) = 0x0102;
        r(sp::kHeaterOpenPercent) = 90;
        r(sp::kHeaterOpenSeconds) = 600;
        r(sp::kOverTemperature) = 3500;
        r(sp::kSensorInstalled) = r(sp::kSensorInstalled + 1) = 0xFFFF;
        r(sp::kPidEnable) = r(sp::kPidEnable + 1) = 0xFFFF;
        // Table: valid marker, 1 module, readings at R0 (10000), working registers at D0 (20000).
        r(5000) = 0xA556;
        r(5001) = 1;
        r(5002) = 10000;
        r(5003) = 20000;
        r(5004) = 0x0101;
        measurement(true);
        heating(true);
    }

    std::uint16_t& r(std::uint32_t i) { return img_.words(Area::R)[i]; }
    std::uint16_t& d(std::uint32_t i) { return img_.words(Area::D)[i]; }
    bool m(std::uint32_t i) const { return img_.bit(Area::M, i); }
    bool y(std::uint32_t i) const { return img_.bit(Area::Y, i); }
    image::Image& image() { return img_; }

    /// Temperature execute code 56h (running) or 00h (idle) in the measurement's WR+0.
    void measurement(bool running) { d(0) = running ? 0x5600 : 0x0000; }
    void en(bool v) { img_.set_bit(Area::M, 0, v); }
    void heating(bool v) { img_.set_bit(Area::M, 1, v); }
    /// Reading of channel c (0.1°).
    void pv(std::uint32_t c, int v) { r(c) = static_cast<std::uint16_t>(v); }
    /// Point i: SP, in-zone offset and gains.
    void point(std::uint32_t i, int sv, int os, int kc, int ki, int td) {
        r(kSv + i) = static_cast<std::uint16_t>(sv);
        r(kOs + i) = static_cast<std::uint16_t>(os);
        r(kPr + i) = static_cast<std::uint16_t>(kc);
        r(kIr + i) = static_cast<std::uint16_t>(ki);
        r(kDr + i) = static_cast<std::uint16_t>(td);
    }

    void scan(int n = 1) {
        for (int k = 0; k < n; ++k) {
            engine::ScanContext ctx{img_, now_, dt_, scans_, scans_ == 0};
            for (auto& i : prog_) i->execute(ctx);
            now_ += dt_;
            ++scans_;
        }
    }
    /// A power-up: the next scan is a first scan, at time 0.
    void power_up() {
        scans_ = 0;
        now_ = Duration{0};
    }
    /// Scans until `d` of simulated time has passed.
    void run_for(Duration d) { scan(static_cast<int>(d / dt_)); }
    Duration now() const { return now_; }
    Duration dt() const { return dt_; }

private:
    config::Config cfg_;
    image::Image img_;
    engine::Program prog_;
    Duration dt_;
    Duration now_{0};
    std::uint64_t scans_ = 0;
};

std::string load_error(const std::string& program) {
    try {
        const config::Config cfg = config::parse_config(config_text(program), "tpctl_test.yaml");
        (void)daemon::build_program(cfg);
    } catch (const config::ConfigError& e) {
        return e.what();
    }
    return "";
}

std::string tpctl(const std::string& operands) { return "  - TPCTL: {" + operands + "}\n"; }

// Checks that the program is refused at tpctl_test.yaml:line:col with `needle` in the message.
void expect_tpctl_error(const std::string& program, int line, int col, const std::string& needle) {
    testing::expect_config_error(testing::config_failure([&] {
                                     const config::Config cfg = config::parse_config(
                                         config_text(program), "tpctl_test.yaml");
                                     (void)daemon::build_program(cfg);
                                 }),
                                 "tpctl_test.yaml", line, col, needle);
}

const char* kOps =
    "en: M0, hc: 1, md: 0, yn: Y30, sn: 0, zn: 10, sv: R100, os: R110, pr: R120, ir: R130, "
    "dr: R140, or: R200, ";

// ---------------------------------------------------------------------------------------------
// Operands (FBs manual §21.7: its program example and operand table)

TEST(Tpctl, OperandsOfTheManualExampleBind) {
    EXPECT_EQ(load_error(kExample), "");
    EXPECT_EQ(load_error(tpctl(std::string(kOps) + "wr: R300, err: M100, alm: M101")), "");
    // ROR and DR areas too, and err/alm optional.
    EXPECT_EQ(load_error(tpctl("en: M0, hc: 1, md: 1, yn: Y0, sn: 0, zn: 32, sv: R5000, "
                               "os: D0, pr: D100, ir: D200, dr: D300, or: R8000, wr: D3991")),
              "");
}

TEST(Tpctl, OperandRangesAreTheManualsAndErrorsNameThePosition) {
    // Sv…WR: R0–R3839, R5000–R8071, D0–D3999 only; a block may not run into R3840.
    expect_tpctl_error(tpctl(std::string(kOps) + "wr: R3835"), 4, 123,
                       "TPCTL.wr: expected 9 register(s) in R0-R3839, R5000-R8071 or "
                       "D0-D3999, got R3835-R3843");
    expect_tpctl_error(tpctl("en: M0, yn: Y30, sn: 0, zn: 10, sv: R3900, os: R110, pr: R120, "
                             "ir: R130, dr: R140, or: R200, wr: R300"),
                       4, 49, "TPCTL.sv: expected 10 register(s)");
    expect_tpctl_error(tpctl("en: M0, yn: Y30, sn: 0, zn: 10, sv: R100, os: R110, pr: R120, "
                             "ir: R130, dr: R140, or: D3995, wr: R300"),
                       4, 99,
                       "TPCTL.or: expected 10 word(s) in R, D, got 'D3995': D3995-D4004 go past "
                       "the last D, D3999");
    expect_tpctl_error(tpctl("en: M0, yn: Y30, sn: 0, zn: 10, sv: WM100, os: R110, pr: R120, "
                             "ir: R130, dr: R140, or: R200, wr: R300"),
                       4, 49, "TPCTL.sv: expected 10 word(s) in R, D, got 'WM100'");
    // Yn is a Y with Zn points.
    expect_tpctl_error(tpctl("en: M0, yn: M30, sn: 0, zn: 10, sv: R100, os: R110, pr: R120, "
                             "ir: R130, dr: R140, or: R200, wr: R300"),
                       4, 25, "TPCTL.yn: expected 10 consecutive device(s) in Y, got 'M30'");
    expect_tpctl_error(tpctl("en: M0, yn: Y250, sn: 0, zn: 10, sv: R100, os: R110, pr: R120, "
                             "ir: R130, dr: R140, or: R200, wr: R300"),
                       4, 25,
                       "TPCTL.yn: expected 10 consecutive device(s) in Y, got 'Y250': Y250-Y259 go "
                       "past the last Y, Y255");
    // A number past what any integer may be is out of range, not "not an integer".
    expect_tpctl_error(tpctl("en: M0, yn: Y30, sn: 0, zn: 99999999999999999999, sv: R100, "
                             "os: R110, pr: R120, ir: R130, dr: R140, or: R200, wr: R300"),
                       4, 41, "TPCTL.zn: 99999999999999999999 is out of range");
    // Md is the constant 0 or 1; unknown operands are typos.
    expect_tpctl_error(tpctl("en: M0, md: 2, yn: Y30, sn: 0, zn: 10, sv: R100, os: R110, pr: R120, "
                             "ir: R130, dr: R140, or: R200, wr: R300"),
                       4, 25, "TPCTL.md: 2 is out of range 0..1");
    expect_tpctl_error(tpctl(std::string(kOps) + "wr: R300, alarm: M101"), 4, 136,
                       "TPCTL: unknown operand 'alarm'");
    expect_tpctl_error(tpctl(std::string(kOps) + "wr: R300, err: R5"), 4, 134,
                       "TPCTL.err: expected a Y, M or S output, got 'R5'");
}

TEST(Tpctl, WorkingRegistersCantBeRepeatedRefusedAtLoad) {
    const std::string first = kExample;
    const std::string second = tpctl(
        "en: M2, hc: 0, yn: Y50, sn: 10, zn: 5, sv: R400, os: R410, pr: R420, ir: R430, "
        "dr: R440, or: R450, wr: R305");
    // Names the second entry's wr and the first entry's position.
    expect_tpctl_error(first + second, 6, 116,
                       "TPCTL.wr: R305-R313 overlaps the working registers R300-R308 of the TPCTL "
                       "at tpctl_test.yaml:4:5 (WR can't be repeated)");
    // Separate WR: accepted.
    EXPECT_EQ(load_error(first + tpctl("en: M2, hc: 0, yn: Y50, sn: 10, zn: 5, sv: R400, "
                                       "os: R410, pr: R420, ir: R430, dr: R440, or: R450, "
                                       "wr: R460")),
              "");
    // One's outputs inside the other's WR, and shared PWM outputs, are refused too.
    expect_tpctl_error(first + tpctl("en: M2, hc: 0, yn: Y50, sn: 10, zn: 5, sv: R400, "
                                     "os: R410, pr: R420, ir: R430, dr: R440, or: R304, "
                                     "wr: R460"),
                       6, 106,
                       "TPCTL.or: R304-R308 overlaps the outputs or working registers of the "
                       "TPCTL at tpctl_test.yaml:4:5");
    expect_tpctl_error(first + tpctl("en: M2, hc: 0, yn: Y35, sn: 10, zn: 5, sv: R400, "
                                     "os: R410, pr: R420, ir: R430, dr: R440, or: R450, "
                                     "wr: R460"),
                       6, 32,
                       "TPCTL.yn: Y35-Y39 overlaps the PWM outputs of the TPCTL at "
                       "tpctl_test.yaml:4:5");
    // An operand inside the instruction's own WR.
    expect_tpctl_error(
        tpctl(std::string(kOps).replace(std::string(kOps).find("sv: R100"), 8, "sv: R305") +
              "wr: R300"),
        4, 63, "TPCTL.sv: R305-R314 overlaps this instruction's working registers R300-R308");
    // Its outputs over its own settings, a flag on its PWM outputs, both flags on one bit: each
    // written twice a scan, and they were accepted.
    const std::string ops(kOps);
    auto with = [&](const std::string& from, const std::string& to) {
        return std::string(ops).replace(ops.find(from), from.size(), to);
    };
    expect_tpctl_error(tpctl(with("or: R200", "or: R100") + "wr: R300"), 4, 113,
                       "TPCTL.or: R100-R109 overlaps this instruction's sv R100-R109");
    expect_tpctl_error(tpctl(kOps + std::string("wr: R300, err: Y31")), 4, 134,
                       "TPCTL.err: Y31 is one of this instruction's PWM outputs Y30-Y39");
    expect_tpctl_error(tpctl(kOps + std::string("wr: R300, err: M7, alm: M7")), 4, 143,
                       "TPCTL.alm: alm is the same bit as err");
}

// FBs manual §21.3: "each module occupies 1 IR and 8 DO"; the declared chain's modules follow
// the FBs-24MC's Y0–Y9, so TC6 has Y10–Y17 and RTD6 Y18–Y25: no program output may land there.
TEST(Tpctl, OutputsOnATemperatureModulesOwnDigitalOutputsAreRefusedAtTheirPosition) {
    const std::string head =
        "profile: fbs\nmodel: FBs-24MC\ntemperature:\n  table: R5000\n"
        "  modules: [TC6:K, RTD6:PT100_DIN]\nprogram:\n";
    auto failure = [&](const std::string& program) {
        return testing::config_failure([&] {
            const config::Config cfg = config::parse_config(head + program, "chain.yaml");
            (void)daemon::build_program(cfg);
        });
    };
    const std::string ops =
        "en: M0, sn: 0, zn: 10, sv: R100, os: R110, pr: R120, ir: R130, dr: R140, or: R200, "
        "wr: R300";
    // yn on the first module's outputs, and a block running into them from below.
    testing::expect_config_error(failure("  - TPCTL: {yn: Y10, " + ops + "}\n"), "chain.yaml", 7,
                                 17, "Y10-Y19 overlaps Y10-Y25");
    testing::expect_config_error(failure("  - TPCTL: {yn: Y1, " + ops + "}\n"), "chain.yaml", 7, 17,
                                 "digital outputs of the temperature modules");
    // ALM on the second module's last output.
    testing::expect_config_error(
        failure("  - TPCTL: {yn: Y30, " + ops + ", alm: Y25}\n"), "chain.yaml", 7,
        static_cast<int>(std::string("  - TPCTL: {yn: Y30, " + ops + ", alm: ").size()) + 1,
        "TPCTL.alm");
    // A word move onto them (WY8 is Y8–Y23).
    testing::expect_config_error(failure("  - MOV: {en: 1, s: R0, d: WY8}\n"), "chain.yaml", 7, 28,
                                 "Y8-Y23 overlaps Y10-Y25");
    // Right after the chain, and with no chain declared, the same outputs are the program's.
    EXPECT_FALSE(failure("  - TPCTL: {yn: Y26, " + ops + "}\n").thrown);
    EXPECT_FALSE(failure("  - MOV: {en: 1, s: R0, d: WY26}\n").thrown);
    EXPECT_EQ(load_error(tpctl("yn: Y10, " + ops)), "");
}

// ---------------------------------------------------------------------------------------------
// Sn / Zn

TEST(Tpctl, SnZnOutOfRangeIsNotExecutedAndErrIsOn) {
    struct Case {
        int sn, zn;
    };
    for (const Case c :
         {Case{30, 5}, Case{32, 1}, Case{0, 0}, Case{0, 33}, Case{-1, 4}, Case{31, 2}}) {
        SCOPED_TRACE(std::to_string(c.sn) + "/" + std::to_string(c.zn));
        // Out-of-range constants are accepted by the loader (docs/profile-fbs.md, FUN86 TPCTL: ERR
        // at run time).
        Rig rig(tpctl("en: M0, hc: 1, yn: Y30, sn: " + std::to_string(c.sn) +
                      ", zn: " + std::to_string(c.zn) +
                      ", sv: R100, os: R110, pr: R120, ir: R130, dr: R140, or: R200, wr: R300, "
                      "err: M100, alm: M101"));
        rig.r(kOr) = 1234;
        rig.r(kWr) = 0xBEEF;
        rig.image().set_bit(Area::Y, kY, true);
        rig.en(true);
        rig.scan(5);
        EXPECT_TRUE(rig.m(100));
        EXPECT_FALSE(rig.m(101));
        // Not executed: nothing of its own is touched, not even the default gains.
        EXPECT_EQ(rig.r(kOr), 1234);
        EXPECT_EQ(rig.r(kWr), 0xBEEF);
        EXPECT_TRUE(rig.y(kY));
        EXPECT_EQ(rig.r(kPr), 0);
    }
}

TEST(Tpctl, SnZnInRangeClearsErr) {
    for (const auto& [sn, zn] : {std::pair{0, 32}, std::pair{31, 1}, std::pair{16, 16}}) {
        Rig rig(tpctl("en: M0, hc: 1, yn: Y0, sn: " + std::to_string(sn) +
                      ", zn: " + std::to_string(zn) +
                      ", sv: R100, os: R140, pr: R180, ir: R220, dr: R260, or: R400, wr: R500, "
                      "err: M100, alm: M101"));
        rig.image().set_bit(Area::M, 100, true);
        rig.en(true);
        rig.scan();
        EXPECT_FALSE(rig.m(100)) << sn << "/" << zn;
    }
}

// ---------------------------------------------------------------------------------------------
// Gate and PV

TEST(Tpctl, RunsOnlyOnceTheTemperatureExecuteCodeIs56h) {
    Rig rig;
    rig.point(0, 1500, 50, 110, 17, 50);
    rig.pv(0, 250);
    rig.en(true);
    for (const int code : {0x0000, 0xFF00, 0xFE00}) {
        rig.d(0) = static_cast<std::uint16_t>(code);
        rig.scan(300);
        EXPECT_EQ(rig.r(kOr), 0) << std::hex << code;
        EXPECT_FALSE(rig.y(kY));
        EXPECT_FALSE(rig.m(101));  // no alarm while not running
    }
    // An invalid table marker stops it too, even with 56h in the working registers.
    rig.d(0) = 0x5600;
    rig.r(5000) = 0x1234;
    rig.scan(10);
    EXPECT_EQ(rig.r(kOr), 0);
    rig.r(5000) = 0xA556;
    rig.scan();
    EXPECT_EQ(rig.r(kOr), 16383);  // 125.0° below SP: full output
    EXPECT_TRUE(rig.y(kY));
    // Back to 00h (a rewritten table being re-read): outputs off again.
    rig.measurement(false);
    rig.scan();
    EXPECT_EQ(rig.r(kOr), 0);
    EXPECT_FALSE(rig.y(kY));
}

TEST(Tpctl, PvOfPointIIsTheReadingOfChannelSnPlusIFromTheTablesReadingStart) {
    // Readings at D100 (SR+2 = 20100), working registers of the measurement at R900 (SR+3 =
    // 10900); points 0–1 are channels 4–5.
    Rig rig(
        tpctl("en: M0, hc: 1, yn: Y30, sn: 4, zn: 2, sv: R100, os: R110, pr: R120, "
              "ir: R130, dr: R140, or: R200, wr: R300, alm: M101"));
    rig.r(5002) = 20100;
    rig.r(5003) = 10900;
    rig.r(900) = 0x5600;
    rig.d(0) = 0;
    rig.point(0, 1000, 10, 100, 0, 0);
    rig.point(1, 1000, 10, 100, 0, 0);
    rig.d(104) = 990;   // channel 4: 1.0° below SP
    rig.d(105) = 1000;  // channel 5: at SP
    rig.pv(4, 0);       // R4/R5 are not where the readings are
    rig.pv(5, 0);
    rig.en(true);
    rig.scan();
    EXPECT_EQ(rig.r(kOr), 1000);  // Kc·E = 100·10
    EXPECT_EQ(rig.r(kOr + 1), 0);
    EXPECT_EQ(rig.r(kWr), 0b11);  // both in zone
}

TEST(Tpctl, PvFromR4004WhenR4003IsA55Ah) {
    Rig rig;
    rig.point(0, 1000, 10, 100, 0, 0);
    rig.pv(0, 500);
    rig.r(600) = 995;  // R4004 = 10600: PVs from R600…
    rig.r(profiles::fbs::special::kTempMeasureRemap) = 0xA55A;
    rig.r(profiles::fbs::special::kTempPvSource) = 10600;
    rig.en(true);
    rig.scan();
    EXPECT_EQ(rig.r(kOr), 500);  // 100·(1000−995)
    // The program supplies those PVs itself, so the module's execute code does not gate them.
    rig.measurement(false);
    rig.r(600) = 990;
    rig.en(false);
    rig.scan();
    rig.en(true);
    rig.scan();
    EXPECT_EQ(rig.r(kOr), 1000);
    // Any other R4003: the table's readings again (and its gate).
    rig.r(profiles::fbs::special::kTempMeasureRemap) = 0;
    rig.measurement(true);
    rig.en(false);
    rig.scan();
    rig.en(true);
    rig.scan();
    EXPECT_EQ(rig.r(kOr), 16383);  // 100·(1000−500) saturates
}

// ---------------------------------------------------------------------------------------------
// Gains

TEST(Tpctl, FirstExecutionGivesDefaultGainsToPointsWhosePrIs0) {
    Rig rig;
    rig.point(3, 1000, 10, 250, 7, 9);  // a tuned point keeps its gains
    rig.pv(0, 0);
    rig.scan(3);
    EXPECT_EQ(rig.r(kPr), 0);  // not executed yet (EN = 0)
    rig.en(true);
    rig.scan();
    for (std::uint32_t i = 0; i < 10; ++i) {
        if (i == 3) continue;
        EXPECT_EQ(rig.r(kPr + i), 110) << i;
        EXPECT_EQ(rig.r(kIr + i), 17) << i;
        EXPECT_EQ(rig.r(kDr + i), 50) << i;
    }
    EXPECT_EQ(rig.r(kPr + 3), 250);
    EXPECT_EQ(rig.r(kIr + 3), 7);
    EXPECT_EQ(rig.r(kDr + 3), 9);
    // Only the first execution: a PR set to 0 later stays 0 (Kc then counts as 1, its minimum).
    rig.r(kPr + 1) = 0;
    rig.en(false);
    rig.scan();
    rig.en(true);
    rig.scan();
    EXPECT_EQ(rig.r(kPr + 1), 0);
}

// A power-up gives a first scan, which starts the instruction as loaded: the next scan with
// EN = 1 is a first execution again (docs/profile-fbs.md, "FUN86 TPCTL").
TEST(Tpctl, APowerUpStartsTheInstructionAsLoaded) {
    Rig rig;
    rig.pv(0, 0);
    rig.en(true);
    rig.scan();
    ASSERT_EQ(rig.r(kPr), 110);
    rig.r(kPr) = 0;
    rig.scan(2);
    EXPECT_EQ(rig.r(kPr), 0);  // no first execution while it runs
    rig.power_up();
    rig.scan();
    EXPECT_EQ(rig.r(kPr), 110);
    EXPECT_EQ(rig.r(kIr), 17);
    EXPECT_EQ(rig.r(kDr), 50);
}

TEST(Tpctl, GainsAreReadEachSolutionFromPrIrDr) {
    Rig rig;
    rig.point(0, 1000, 10, 7, 0, 0);
    rig.pv(0, 900);
    rig.en(true);
    rig.scan();
    EXPECT_EQ(rig.r(kOr), 700);
    rig.r(kPr) = 9;
    rig.run_for(4s);  // next solution
    EXPECT_EQ(rig.r(kOr), 900);
    rig.r(kPr) = 0;  // below the range: Kc 1
    rig.run_for(4s);
    EXPECT_EQ(rig.r(kOr), 100);
}

// ---------------------------------------------------------------------------------------------
// R4005

// Times at which OR changed while the error stays constant and the integral keeps growing.
std::vector<Duration> solution_times(std::uint16_t r4005, Duration span) {
    Rig rig;
    rig.r(profiles::fbs::special::kPidTiming) = r4005;
    rig.point(0, 1000, 10, 100, 100, 0);  // E = 1.0°, inside the band: integrates each time
    rig.pv(0, 990);
    rig.en(true);
    std::vector<Duration> t;
    std::uint16_t last = 0xFFFF;
    while (rig.now() < span) {
        const Duration at = rig.now();
        rig.scan();
        if (rig.r(kOr) != last) t.push_back(at);
        last = rig.r(kOr);
    }
    return t;
}

TEST(Tpctl, SolutionIntervalFromR4005LowByte) {
    const std::pair<std::uint16_t, Duration> cases[] = {{0x0100, 1s}, {0x0101, 2s},  {0x0102, 4s},
                                                        {0x0103, 8s}, {0x0104, 16s}, {0x0105, 32s},
                                                        {0x0109, 32s}};
    for (const auto& [code, ts] : cases) {
        const auto t = solution_times(code, ts * 4 + 1ms);
        ASSERT_EQ(t.size(), 5u) << std::hex << code;
        for (std::size_t k = 0; k < t.size(); ++k) EXPECT_EQ(t[k], ts * static_cast<int>(k));
    }
}

// Rising edges of Y30 with OR at half scale.
std::vector<Duration> pwm_starts(Rig& rig, Duration span) {
    std::vector<Duration> t;
    bool last = false;
    const Duration end = rig.now() + span;
    while (rig.now() < end) {
        const Duration at = rig.now();
        rig.scan();
        if (rig.y(kY) && !last) t.push_back(at);
        last = rig.y(kY);
    }
    return t;
}

TEST(Tpctl, PwmCycleFromR4005HighByte) {
    const std::pair<std::uint16_t, Duration> cases[] = {{0x0002, 1s}, {0x0102, 2s},  {0x0202, 4s},
                                                        {0x0302, 8s}, {0x0402, 16s}, {0x0502, 32s},
                                                        {0xFF02, 32s}};
    for (const auto& [code, cycle] : cases) {
        Rig rig;
        rig.r(profiles::fbs::special::kPidTiming) = code;
        rig.point(0, 1000, 10, 10, 0, 0);
        rig.pv(0, 1000 - 819);  // OR 8190: about half the cycle
        rig.en(true);
        const auto t = pwm_starts(rig, cycle * 3);
        ASSERT_EQ(t.size(), 3u) << std::hex << code;
        for (std::size_t k = 0; k < t.size(); ++k) EXPECT_EQ(t[k], cycle * static_cast<int>(k));
        EXPECT_EQ(rig.r(kWr + 4) >> 8, std::chrono::duration_cast<std::chrono::seconds>(cycle)
                                           .count());  // WR+4 high byte: the cycle in effect
    }
}

TEST(Tpctl, R4005IsReadWhenEnRisesOnly) {
    Rig rig;
    rig.point(0, 1000, 10, 100, 100, 0);
    rig.pv(0, 990);
    rig.en(true);
    rig.scan();
    EXPECT_EQ(rig.r(kWr + 4), 0x0204);                   // defaults: 4 s solution, 2 s PWM
    rig.r(profiles::fbs::special::kPidTiming) = 0x0000;  // changed while EN = 1: waits
    const std::uint16_t before = rig.r(kOr);
    rig.run_for(1s);
    EXPECT_EQ(rig.r(kOr), before);  // no solution after 1 s
    EXPECT_EQ(rig.r(kWr + 4), 0x0204);
    rig.en(false);
    rig.scan();
    rig.en(true);
    rig.scan();
    EXPECT_EQ(rig.r(kWr + 4), 0x0101);
    const std::uint16_t after = rig.r(kOr);
    rig.run_for(1s);
    EXPECT_NE(rig.r(kOr), after);  // now every second
}

// ---------------------------------------------------------------------------------------------
// The PID law

TEST(Tpctl, ProportionalBandOfKc110Is14Point9Degrees) {
    // Kc·E alone, E in 0.1°, reaches 16383 at the proportional band: 16383 / 110 = 148.9.
    for (const auto& [e, out] : {std::pair{149, 16383}, std::pair{148, 16280},
                                 std::pair{100, 11000}, std::pair{1, 110}, std::pair{0, 0}}) {
        Rig rig;
        rig.point(0, 1500, 10, 110, 0, 0);
        rig.pv(0, 1500 - e);
        rig.en(true);
        rig.scan();
        EXPECT_EQ(rig.r(kOr), out) << e;
    }
}

TEST(Tpctl, IntegralAddsKcKiTsPerSolution) {
    // Kc 100, Ki 60 (0.6 repeats/min), Ts 1 s, E 10: each solution adds 100·0.6·(1/60)·10 = 10.
    Rig rig;
    rig.r(profiles::fbs::special::kPidTiming) = 0x0100;
    rig.point(0, 1000, 5, 100, 60, 0);
    rig.pv(0, 990);
    rig.en(true);
    rig.scan();
    EXPECT_EQ(rig.r(kOr), 1010);
    rig.run_for(1s);
    EXPECT_EQ(rig.r(kOr), 1020);
    rig.run_for(3s);
    EXPECT_EQ(rig.r(kOr), 1050);
    // At E = 0 the integral holds the output (what removes the steady-state error).
    rig.pv(0, 1000);
    rig.run_for(1s);
    EXPECT_EQ(rig.r(kOr), 50);
}

TEST(Tpctl, DerivativeActsAgainstTheChangeOfPv) {
    // Kc 10, Td 100 (1 min = 60 s), Ts 4 s: −Kc·60·ΔPV/4 = −150·ΔPV.
    Rig rig;
    rig.point(0, 1000, 5, 10, 0, 100);
    rig.pv(0, 200);
    rig.en(true);
    rig.scan();
    EXPECT_EQ(rig.r(kOr), 8000);  // first solution: no previous PV, no derivative kick
    rig.pv(0, 202);               // rising towards SP: less output
    rig.run_for(4s);
    EXPECT_EQ(rig.r(kOr), 7980 - 300);
    rig.pv(0, 200);  // falling: more output
    rig.run_for(4s);
    EXPECT_EQ(rig.r(kOr), 8000 + 300);
    rig.run_for(4s);  // steady: no derivative
    EXPECT_EQ(rig.r(kOr), 8000);
}

TEST(Tpctl, IntegralIsClampedNoWindup) {
    // Md 1 (always integrating), 50° below SP for 10 minutes: P alone saturates the output, so
    // the integral must not grow; when PV then crosses SP the output drops at once.
    Rig rig(std::string(kExample).replace(std::string(kExample).find("md: 0"), 5, "md: 1"));
    rig.r(profiles::fbs::special::kPidTiming) = 0x0100;
    rig.point(0, 1000, 5, 110, 100, 0);
    rig.pv(0, 500);
    rig.en(true);
    rig.run_for(600s);
    EXPECT_EQ(rig.r(kOr), 16383);
    rig.pv(0, 1001);
    rig.run_for(1s);
    EXPECT_EQ(rig.r(kOr), 0);
    // And the integral never goes below 0 either: far above SP for long, then at SP − 1.0°.
    rig.pv(0, 1500);
    rig.run_for(600s);
    rig.pv(0, 990);
    rig.run_for(1s);
    // 1100 (P) + 110·1·(1/60)·10 = 18.3 (one integral step from 0).
    EXPECT_EQ(rig.r(kOr), 1118);
    // Inside the band, the integral stops where the output reaches full scale.
    rig.pv(0, 900);  // P = 11000
    rig.run_for(300s);
    EXPECT_EQ(rig.r(kOr), 16383);
    rig.pv(0, 1000);  // E = 0: output = the integral = what was left below full scale
    rig.run_for(1s);
    EXPECT_LE(rig.r(kOr), 16383 - 11000 + 200);
    EXPECT_GE(rig.r(kOr), 16383 - 11000);
}

TEST(Tpctl, HeatingErrorIsSpMinusPvCoolingIsPvMinusSp) {
    Rig rig;
    rig.point(0, 1000, 5, 10, 0, 0);
    rig.pv(0, 1100);  // 10° above SP
    rig.en(true);
    rig.scan();
    EXPECT_EQ(rig.r(kOr), 0);  // heating: E = −100
    rig.heating(false);
    rig.scan();
    EXPECT_EQ(rig.r(kOr), 1000);  // cooling: E = +100, solved at once on the change
    rig.pv(0, 900);
    rig.run_for(4s);
    EXPECT_EQ(rig.r(kOr), 0);
}

TEST(Tpctl, Md0IntegratesOnlyInsideTheProportionalBandMd1Always) {
    // Kc 10 (band 1638 = 163.8°), Ki 600 (each 1 s solution adds E), Td 100 (D = −600·ΔPV).
    // PV 200° below SP and rising 6° a second: outside the band, the derivative holds the
    // output at 0, so nothing saturates high and "universal" integrates; Md 0 does not.
    auto run = [](int md) {
        Rig rig(std::string(kExample).replace(std::string(kExample).find("md: 0"), 5,
                                              "md: " + std::to_string(md)));
        rig.r(profiles::fbs::special::kPidTiming) = 0x0100;
        rig.point(0, 3000, 5, 10, 600, 100);
        rig.pv(0, 1000);
        rig.en(true);
        rig.scan();
        for (int pv : {1060, 1120, 1180}) {
            rig.pv(0, pv);
            rig.run_for(1s);
        }
        EXPECT_EQ(rig.r(kOr), 0);
        rig.pv(0, 3000);
        rig.run_for(2s);  // two solutions at SP: E = 0 and, the second time, ΔPV = 0
        return rig.r(kOr);
    };
    EXPECT_EQ(run(0), 0);                   // nothing accumulated outside the band
    EXPECT_EQ(run(1), 1940 + 1880 + 1820);  // the integral alone
}

// ---------------------------------------------------------------------------------------------
// PWM

// Scans with Y30 ON in each of `cycles` PWM cycles.
std::vector<int> on_scans(Rig& rig, Duration cycle, int cycles) {
    std::vector<int> n;
    for (int c = 0; c < cycles; ++c) {
        int on = 0;
        for (int k = 0; k < cycle / rig.dt(); ++k) {
            rig.scan();
            on += rig.y(kY) ? 1 : 0;
        }
        n.push_back(on);
    }
    return n;
}

TEST(Tpctl, PwmYIsOnForOrOver16383OfEachCycle) {
    // P only, Kc 1: OR = E. 2 s cycle, 10 ms scans.
    for (const auto& [e, scans] : {std::pair{4096, 50}, std::pair{8192, 100}, std::pair{16383, 200},
                                   std::pair{0, 0}, std::pair{12288, 150}, std::pair{81, 1}}) {
        Rig rig;
        rig.point(0, 20000, 5, 1, 0, 0);
        rig.pv(0, 20000 - e);
        rig.en(true);
        const auto n = on_scans(rig, 2s, 3);
        for (int v : n) EXPECT_EQ(v, scans) << "OR " << e;
    }
}

TEST(Tpctl, PwmOnTimeStartsTheCycleAndFollowsTheScanGranularity) {
    // 30 ms scans: 25 % of 2 s = 500 ms is 16.7 scans → 17 (to the nearest scan).
    Rig rig(kExample, 30ms);
    rig.point(0, 20000, 5, 1, 0, 0);
    rig.pv(0, 20000 - 4096);
    rig.en(true);
    rig.scan();
    EXPECT_TRUE(rig.y(kY));
    int on = 1;
    bool seen_off = false;
    for (int k = 1; k < 66; ++k) {  // the rest of the first 2 s cycle (66 scans of 30 ms)
        rig.scan();
        if (rig.y(kY)) {
            EXPECT_FALSE(seen_off) << "one pulse per cycle";
            ++on;
        } else {
            seen_off = true;
        }
    }
    EXPECT_EQ(on, 17);
}

TEST(Tpctl, PwmNewOutputTakesEffectAtTheNextCycle) {
    // Ts 1 s, PWM 2 s: an output changed mid-cycle waits for the next cycle (one pulse each).
    Rig rig;
    rig.r(profiles::fbs::special::kPidTiming) = 0x0100;
    rig.point(0, 20000, 5, 1, 0, 0);
    rig.pv(0, 20000 - 4096);
    rig.en(true);
    rig.run_for(1s);
    rig.pv(0, 20000 - 16383);  // solved at 1 s: OR 16383
    const auto n = on_scans(rig, 1s, 1);
    EXPECT_EQ(rig.r(kOr), 16383);
    EXPECT_EQ(n[0], 0);  // rest of the first cycle: still the 25 % pulse, already over
    EXPECT_EQ(on_scans(rig, 2s, 1)[0], 200);
}

// ---------------------------------------------------------------------------------------------
// R4012/R4013, EN

TEST(Tpctl, R4012R4013BitZeroMeansNoPidYOffOr0) {
    Rig rig(
        tpctl("en: M0, hc: 1, yn: Y0, sn: 0, zn: 32, sv: R100, os: R140, pr: R180, "
              "ir: R220, dr: R260, or: R400, wr: R500, alm: M101"));
    for (std::uint32_t c = 0; c < 32; ++c) {
        rig.r(100 + c) = 1000;
        rig.r(140 + c) = 10;
        rig.r(180 + c) = 10;
        rig.pv(c, 500);
    }
    rig.r(profiles::fbs::special::kPidEnable) = 0xFFFF & ~(1u << 3);
    rig.r(profiles::fbs::special::kPidEnable + 1) = 0xFFFF & ~(1u << 4);  // channel 20
    rig.en(true);
    rig.scan();
    for (std::uint32_t c = 0; c < 32; ++c) {
        const bool off = c == 3 || c == 20;
        EXPECT_EQ(rig.r(400 + c), off ? 0 : 5000) << c;
        EXPECT_EQ(rig.y(c), !off) << c;
    }
    // A disabled point that is out of zone does not raise ALM.
    for (std::uint32_t c = 0; c < 32; ++c) rig.pv(c, c == 3 || c == 20 ? 0 : 1000);
    rig.run_for(4s);
    EXPECT_EQ(rig.r(500), 0xFFFF & ~(1u << 3));
    EXPECT_EQ(rig.r(501), 0xFFFF & ~(1u << 4));
    EXPECT_FALSE(rig.m(101));
    // Enabled again: PID resumes at the next solution.
    rig.r(profiles::fbs::special::kPidEnable) = 0xFFFF;
    rig.run_for(4s);
    EXPECT_EQ(rig.r(403), 10000);
}

TEST(Tpctl, EnOffTurnsAllItsYOffOr0AndResetsThePidState) {
    Rig rig;
    rig.r(profiles::fbs::special::kPidTiming) = 0x0100;
    for (std::uint32_t i = 0; i < 10; ++i) {
        rig.point(i, 1000, 5, 100, 600, 0);
        rig.pv(i, 990);
    }
    rig.en(true);
    rig.run_for(10s);  // the integral grows by 100 a second
    EXPECT_GT(rig.r(kOr), 1900);
    rig.scan();  // a PWM cycle starts
    EXPECT_TRUE(rig.y(kY + 9));
    rig.en(false);
    rig.scan();
    for (std::uint32_t i = 0; i < 10; ++i) {
        EXPECT_EQ(rig.r(kOr + i), 0);
        EXPECT_FALSE(rig.y(kY + i));
    }
    EXPECT_FALSE(rig.m(101));
    rig.r(kOr) = 777;  // held at 0 while EN = 0
    rig.scan();
    EXPECT_EQ(rig.r(kOr), 0);
    rig.en(true);
    rig.scan();
    EXPECT_EQ(rig.r(kOr), 1000 + 100);  // a fresh start: P + one integral step
}

// ---------------------------------------------------------------------------------------------
// Zone, warnings, ALM

TEST(Tpctl, InZoneIsSpMinusOsToSpPlusOsInWr0AndWr1) {
    Rig rig(
        tpctl("en: M0, hc: 1, yn: Y0, sn: 0, zn: 32, sv: R100, os: R140, pr: R180, "
              "ir: R220, dr: R260, or: R400, wr: R500, alm: M101"));
    for (std::uint32_t c = 0; c < 32; ++c) {
        rig.r(100 + c) = 2000;
        rig.r(140 + c) = 50;
        rig.pv(c, 2000);
    }
    rig.pv(1, 1950);   // SP − Os: in
    rig.pv(2, 1949);   // out
    rig.pv(3, 2050);   // SP + Os: in
    rig.pv(4, 2051);   // out
    rig.pv(20, 1900);  // out, WR+1 bit 4
    rig.en(true);
    rig.scan();
    EXPECT_EQ(rig.r(500), 0xFFFF & ~((1u << 2) | (1u << 4)));
    EXPECT_EQ(rig.r(501), 0xFFFF & ~(1u << 4));
    rig.pv(2, 1990);
    rig.scan();
    EXPECT_EQ(rig.r(500), 0xFFFF & ~(1u << 4));
}

TEST(Tpctl, OverTemperatureAfter10ConsecutiveScansAtOrAboveR4008) {
    Rig rig;
    rig.r(profiles::fbs::special::kOverTemperature) = 2000;
    for (std::uint32_t i = 0; i < 10; ++i) {
        rig.point(i, 1990, 20, 110, 17, 50);
        rig.pv(i, 1990);
    }
    rig.en(true);
    rig.scan();
    EXPECT_FALSE(rig.m(101));
    rig.pv(2, 2000);
    rig.scan(9);
    EXPECT_EQ(rig.r(kWr + 2), 0);
    rig.pv(2, 1999);  // one scan below: the count starts again
    rig.scan();
    rig.pv(2, 2005);
    rig.scan(9);
    EXPECT_EQ(rig.r(kWr + 2), 0);
    rig.scan();
    EXPECT_EQ(rig.r(kWr + 2), 1u << 2);
    EXPECT_EQ(rig.r(kWr + 5), 1u << 2);  // the cause: over-temperature
    EXPECT_EQ(rig.r(kWr + 7), 0);
    EXPECT_TRUE(rig.m(101));
    // Clears when it no longer holds.
    rig.pv(2, 1995);
    rig.scan();
    EXPECT_EQ(rig.r(kWr + 2), 0);
    EXPECT_EQ(rig.r(kWr + 5), 0);
    EXPECT_FALSE(rig.m(101));
}

TEST(Tpctl, OverTemperatureOfPoints16To31IsInWr3) {
    Rig rig(
        tpctl("en: M0, hc: 1, yn: Y0, sn: 0, zn: 32, sv: R100, os: R140, pr: R180, "
              "ir: R220, dr: R260, or: R400, wr: R500, alm: M101"));
    for (std::uint32_t c = 0; c < 32; ++c) {
        rig.r(100 + c) = 1000;
        rig.r(140 + c) = 10;
        rig.pv(c, 1000);
    }
    rig.pv(17, 3600);  // above the default R4008 = 3500
    rig.en(true);
    rig.scan(10);
    EXPECT_EQ(rig.r(502), 0);
    EXPECT_EQ(rig.r(503), 1u << 1);
    EXPECT_EQ(rig.r(506), 1u << 1);
}

TEST(Tpctl, OverTemperatureIsWatchedAlsoOnPointsWithoutPid) {
    // A shorted SSR heats a point whatever R4012 says: the warning still comes after 10 scans.
    Rig rig;
    for (std::uint32_t i = 0; i < 10; ++i) {
        rig.point(i, 1000, 10, 110, 17, 50);
        rig.pv(i, 1000);
    }
    rig.r(profiles::fbs::special::kPidEnable) = 0xFFFF & ~(1u << 6);
    rig.pv(6, 3600);
    rig.en(true);
    rig.scan(9);
    EXPECT_EQ(rig.r(kWr + 2), 0);
    EXPECT_FALSE(rig.m(101));
    rig.scan();
    EXPECT_EQ(rig.r(kWr + 2), 1u << 6);
    EXPECT_EQ(rig.r(kWr + 5), 1u << 6);
    EXPECT_TRUE(rig.m(101));
    EXPECT_EQ(rig.r(kOr + 6), 0);  // still no PID
    rig.pv(6, 3400);
    rig.scan();
    EXPECT_EQ(rig.r(kWr + 2), 0);
    EXPECT_FALSE(rig.m(101));
}

TEST(Tpctl, HeaterOpenAfterHighOutputForR4007SecondsWhileOutOfZone) {
    Rig rig;
    rig.r(profiles::fbs::special::kHeaterOpenPercent) = 90;
    rig.r(profiles::fbs::special::kHeaterOpenSeconds) = 60;
    rig.point(0, 1500, 50, 110, 17, 50);
    rig.pv(0, 250);  // cold: output at full scale
    rig.en(true);
    rig.run_for(60s);  // 0 … 59.99 s
    EXPECT_EQ(rig.r(kOr), 16383);
    EXPECT_EQ(rig.r(kWr + 2), 0);
    rig.scan();  // 60 s after the output went high
    EXPECT_EQ(rig.r(kWr + 2), 1u);
    EXPECT_EQ(rig.r(kWr + 7), 1u);  // the cause: heater open
    EXPECT_EQ(rig.r(kWr + 5), 0);
    EXPECT_TRUE(rig.m(101));
    // Clears when the condition no longer holds: in zone.
    rig.pv(0, 1480);
    rig.scan();
    EXPECT_EQ(rig.r(kWr + 2), 0);
    EXPECT_EQ(rig.r(kWr + 7), 0);
}

TEST(Tpctl, HeaterOpenNeedsOutputAtLeastR4006PercentContinuously) {
    // Kc 10: OR = 10·E. 90 % of 16383 is 14744.7.
    Rig rig;
    rig.r(profiles::fbs::special::kHeaterOpenSeconds) = 60;
    rig.point(0, 3000, 50, 10, 0, 0);  // below R4008: no over-temperature
    rig.pv(0, 3000 - 1474);            // OR 14740 < 90 %
    rig.en(true);
    rig.run_for(120s);
    EXPECT_EQ(rig.r(kOr), 14740);
    EXPECT_EQ(rig.r(kWr + 2), 0);
    rig.pv(0, 3000 - 1475);  // OR 14750 ≥ 90 %
    rig.run_for(40s);
    rig.pv(0, 3000 - 1474);  // one solution below: the time starts again
    rig.run_for(4s);
    rig.pv(0, 3000 - 1475);
    rig.run_for(60s);  // solved at 164 s: high for 59.99 s
    EXPECT_EQ(rig.r(kWr + 2), 0);
    rig.scan();
    EXPECT_EQ(rig.r(kWr + 2), 1u);
    EXPECT_EQ(rig.r(kWr + 7), 1u);
    // R4006 = 100: only a full-scale output counts; the warning clears.
    rig.r(profiles::fbs::special::kHeaterOpenPercent) = 100;
    rig.scan();
    EXPECT_EQ(rig.r(kWr + 2), 0);
}

TEST(Tpctl, AlmIsAnyPointOutOfZoneOrAnyWarning) {
    Rig rig;
    for (std::uint32_t i = 0; i < 10; ++i) {
        rig.point(i, 1000, 10, 110, 17, 50);
        rig.pv(i, 1000);
    }
    rig.en(true);
    rig.scan();
    EXPECT_EQ(rig.r(kWr), 0x03FF);
    EXPECT_FALSE(rig.m(101));
    rig.pv(9, 1011);
    rig.scan();
    EXPECT_TRUE(rig.m(101));
    rig.pv(9, 1010);
    rig.scan();
    EXPECT_FALSE(rig.m(101));
    // A warning alone (in zone, over R4008) raises it too.
    rig.r(profiles::fbs::special::kOverTemperature) = 1000;
    rig.scan(10);
    EXPECT_EQ(rig.r(kWr), 0x03FF);
    EXPECT_TRUE(rig.m(101));
}

TEST(Tpctl, BrokenSensorReadingTurnsTheOutputOffAndIsOutOfZone) {
    Rig rig;
    rig.point(0, 1500, 50, 110, 17, 50);
    rig.point(1, 1500, 50, 110, 17, 50);
    rig.pv(0, 1500);
    rig.pv(1, 1400);
    rig.en(true);
    rig.scan();
    EXPECT_GT(rig.r(kOr + 1), 0);
    rig.pv(1, 32767);  // 7FFFh
    rig.scan(20);
    EXPECT_EQ(rig.r(kOr + 1), 0);
    EXPECT_FALSE(rig.y(kY + 1));
    EXPECT_EQ(rig.r(kWr) & 3u, 1u);  // point 1 not in zone
    EXPECT_EQ(rig.r(kWr + 2), 0);    // not an over-temperature: there is no temperature
    EXPECT_TRUE(rig.m(101));
    // The same with the cooling action (a broken sensor never means full cooling either).
    rig.heating(false);
    rig.scan(5);
    EXPECT_EQ(rig.r(kOr + 1), 0);
    // Sensor back: control resumes from a fresh start.
    rig.heating(true);
    rig.pv(1, 1400);
    rig.scan();
    EXPECT_EQ(rig.r(kOr + 1), 11125);  // P + one integral step: 11000 + 110·0.17·(4/60)·100
}

// ---------------------------------------------------------------------------------------------
// Points and instructions

TEST(Tpctl, UpTo32PointsEachOnItsChannelAndY) {
    Rig rig(
        tpctl("en: M0, hc: 1, yn: Y0, sn: 0, zn: 32, sv: R100, os: R140, pr: R180, "
              "ir: R220, dr: R260, or: R400, wr: R500, alm: M101"));
    for (std::uint32_t c = 0; c < 32; ++c) {
        rig.r(100 + c) = 1000;
        rig.r(140 + c) = 5;
        rig.r(180 + c) = 1;
        rig.pv(c, static_cast<int>(1000 - 100 * (c + 1)));  // OR = 100·(c+1)
    }
    rig.en(true);
    rig.scan();
    for (std::uint32_t c = 0; c < 32; ++c) {
        EXPECT_EQ(rig.r(400 + c), 100 * (c + 1)) << c;
        EXPECT_TRUE(rig.y(c)) << c;
    }
    EXPECT_EQ(rig.r(220), 0);  // Kc given, so no defaults
}

TEST(Tpctl, SeveralInstructionsKeepSeparateState) {
    // Heating on channels 0–4 (Y30…), cooling on 5–9 (Y50…), separate WR and enables.
    Rig rig(tpctl("en: M0, hc: 1, md: 0, yn: Y30, sn: 0, zn: 5, sv: R100, os: R110, pr: R120, "
                  "ir: R130, dr: R140, or: R200, wr: R300, err: M100, alm: M101") +
            tpctl("en: M2, hc: 0, md: 1, yn: Y50, sn: 5, zn: 5, sv: R105, os: R115, pr: R125, "
                  "ir: R135, dr: R145, or: R205, wr: R310, err: M102, alm: M103"));
    for (std::uint32_t i = 0; i < 10; ++i) {
        rig.point(i, 1000, 10, 10, 0, 0);
        rig.pv(i, i < 5 ? 900 : 1100);  // heating below SP, cooling above
    }
    rig.en(true);
    rig.image().set_bit(Area::M, 2, true);
    rig.scan();
    for (std::uint32_t i = 0; i < 10; ++i) EXPECT_EQ(rig.r(kOr + i), 1000) << i;
    EXPECT_TRUE(rig.y(30));
    EXPECT_TRUE(rig.y(50));
    EXPECT_TRUE(rig.m(101));
    EXPECT_TRUE(rig.m(103));
    // One off: the other keeps running.
    rig.image().set_bit(Area::M, 2, false);
    rig.pv(0, 1000);
    rig.run_for(4s);
    EXPECT_EQ(rig.r(kOr), 0);
    EXPECT_EQ(rig.r(kOr + 1), 1000);
    EXPECT_EQ(rig.r(kOr + 5), 0);
    EXPECT_FALSE(rig.m(103));
    EXPECT_EQ(rig.r(300), 0b00001);
    EXPECT_EQ(rig.r(310), 0);
}

}  // namespace
}  // namespace plcemu::profiles::fbs
