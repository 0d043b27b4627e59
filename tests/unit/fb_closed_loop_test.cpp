// Closed loops of the FB's PID (FB manual FUN73/FUN86; docs/profile-fb.md, "Tuning"), in virtual
// time on the whole PLC: config/fb-tpctl.yaml's 24 TPCTL points with the default gains on its
// slow plant, and a TSTC with the default Td on the default (fast) plant, which limit-cycles.

#include <gtest/gtest.h>

#include <algorithm>
#include <cstdint>
#include <fstream>
#include <iostream>
#include <sstream>
#include <string>

#include "plcemu/config/config.hpp"
#include "plcemu/daemon/plc.hpp"
#include "plcemu/plant/plant.hpp"

namespace plcemu {
namespace {

using image::Area;

constexpr int kScansPerSecond = 100;  // scan_ms 10

std::string file_text(const std::string& name) {
    std::ifstream in(std::string(PLCEMU_SOURCE_DIR) + "/config/" + name);
    std::ostringstream text;
    text << in.rdbuf();
    return text.str();
}

/// Readings of points 0…n−1 (R0…) over a run, second by second.
struct Figures {
    int reached_s = -1;   // first second every reading is within SP ± 5
    double peak_c = 0.0;  // highest true temperature, °C
    int low = 32767;      // lowest reading over the last 600 s
    int high = -32768;    // highest reading over the last 600 s
    int last_out_s = 0;   // last second a reading was outside SP ± 5
};

Figures run(daemon::Plc& plc, int points, int sp, int seconds) {
    Figures r;
    for (int s = 1; s <= seconds; ++s) {
        plc.engine().run_scans(kScansPerSecond, {});
        bool all_in = true;
        for (int p = 0; p < points; ++p) {
            const auto v =
                static_cast<std::int16_t>(plc.image().word(Area::R, static_cast<std::uint32_t>(p)));
            r.peak_c = std::max(r.peak_c, plc.plant().true_temperature(p));
            if (v < sp - 5 || v > sp + 5) all_in = false;
            if (s > seconds - 600) {
                r.low = std::min<int>(r.low, v);
                r.high = std::max<int>(r.high, v);
            }
        }
        if (all_in && r.reached_s < 0) r.reached_s = s;
        if (!all_in) r.last_out_s = s;
    }
    return r;
}

// config/fb-tpctl.yaml: TPSNS + TPCTL on 24 points, the first execution's Kc 60, Ti 17, Td 100,
// R4005 0000h, plant K 400, τ 1200 s, θ 60 s, 25 °C, SP 150 ± 5: settled within the band.
TEST(FbClosedLoop, TpctlDefaultGainsSettleOnTheSlowPlant) {
    daemon::Plc plc(config::parse_config(file_text("fb-tpctl.yaml"), "fb-tpctl.yaml"));
    const Figures r = run(plc, 24, 150, 1800);
    std::cout << "fb-tpctl.yaml: within 150 +- 5 from " << r.last_out_s << " s, peak " << r.peak_c
              << " degC, last 10 min " << r.low << ".." << r.high << "\n";
    EXPECT_LE(r.last_out_s, 1200);
    EXPECT_LE(r.peak_c, 158.0);
    EXPECT_GE(r.low, 147);
    EXPECT_LE(r.high, 153);
    EXPECT_EQ(plc.image().word(Area::R, 400), 0xFFFF);
    EXPECT_EQ(plc.image().word(Area::R, 401), 0x00FF);
}

// A TSTC with the default gains (Kc 60, Ti 17, Td 100) on the default plant (K 400, τ 120 s,
// θ 5 s): one 1 °C step of the reading moves the output by Kc·60 s/Ts·G ≈ 7400 counts, and the
// loop limit-cycles far above SP 150.
TEST(FbClosedLoop, TstcDefaultTdLimitCyclesOnTheFastPlant) {
    daemon::Plc plc(config::parse_config(
        "profile: fb\nscan_ms: 10\ninit:\n  M0: 1\n  R100: [150, 150, 150, 150]\n"
        "  R120: [5, 5, 5, 5]\nprogram:\n"
        "  - TSTC: {en: M0, hc: 1, tp: 0, pl: 0, sm: 0, ym: Y16, ar: R3842, tr: R0, yh: Y48, "
        "sh: 0, zh: 4, sv: R100, os: R120, pr: R140, ir: R160, dr: R180, or: R300, wr: R200}\n",
        "fast.yaml"));
    const Figures r = run(plc, 4, 150, 1800);
    std::cout << "default Td, fast plant: peak " << r.peak_c << " degC, last 10 min " << r.low
              << ".." << r.high << "\n";
    EXPECT_EQ(plc.image().word(Area::R, 180), 100);
    EXPECT_GT(r.high - r.low, 10);
    EXPECT_GT(r.high, 180);
}

}  // namespace
}  // namespace plcemu
