// Closed loop (FBs manual §21.7 with §21.3): FUN86 TPCTL heating config/default.yaml's plant
// through the temperature measurement, in virtual time, on the whole PLC built from that file.

#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <fstream>
#include <iostream>
#include <sstream>
#include <string>
#include <vector>

#include "plcemu/config/config.hpp"
#include "plcemu/daemon/plc.hpp"
#include "profiles/fbs/special_registers.hpp"
#include "plcemu/image/image.hpp"

namespace plcemu {
namespace {

using image::Area;
using namespace std::chrono_literals;

constexpr int kPoints = 10;
constexpr int kSp = 1500;  // 150.0 °C
constexpr int kBand = 50;  // ±5.0 °C
constexpr std::uint32_t kOr = 200, kWr = 300, kY = 30;
constexpr std::uint32_t kAlm = 101;

// config/default.yaml as shipped: the FBs manual's FUN86 example (§21.7) with its indicator
// moves, R4005 at the system default 0102h (4 s solution, 2 s PWM), TC6 (K) on channels 0–5 and
// RTD6 (Pt100) on 6–9, SP 150.0 °C, in-zone ±5.0 °C, default gains (PR = 0 at the first
// execution), on its plant (K 400 °C, τ 1200 s, θ 60 s, ambient 25 °C, no noise). `extra_init`
// adds presets at the top of `init:`.
std::string config_text(const std::string& extra_init = "") {
    const std::string path = std::string(PLCEMU_SOURCE_DIR) + "/config/default.yaml";
    std::ifstream in(path);
    std::ostringstream text;
    text << in.rdbuf();
    std::string s = text.str();
    const std::size_t init = s.find("\ninit:\n");
    if (init == std::string::npos) {
        ADD_FAILURE() << path << " has no init: section";
        return s;
    }
    return s.insert(init + 7, extra_init);
}

/// Per-point figures of a step response (readings, as the PLC sees them).
struct Step {
    int max = -32768;      // highest reading, 0.1 °C
    double settled_s = 0;  // simulated time of the last reading outside SP ± 5.0 °C
    int last = 0;          // last reading
    int low = 32767;       // lowest reading over the last 600 s
    int high = -32768;     // highest reading over the last 600 s
    bool in_zone_at_end = false;

    double overshoot() const { return (max - kSp) / 10.0; }
};

/// The whole PLC of a config, scanned in virtual time.
class Loop {
public:
    explicit Loop(const std::string& text)
        : cfg_(config::parse_config(text, "closed_loop.yaml")),
          plc_(cfg_) {}

    image::Image& img() { return plc_.image(); }
    plant::Plant& plant() { return plc_.plant(); }
    std::uint16_t& r(std::uint32_t i) { return img().words(Area::R)[i]; }
    int reading(int c) { return static_cast<std::int16_t>(r(static_cast<std::uint32_t>(c))); }
    double seconds() { return std::chrono::duration<double>(plc_.engine().now()).count(); }

    /// Sets M0 and M800–M809, as the SCADA of the manual's example does.
    void start() {
        img().set_bit(Area::M, 0, true);
        for (std::uint32_t i = 0; i < kPoints; ++i) img().set_bit(Area::M, 800 + i, true);
    }
    void scan() { plc_.engine().run_scans(1); }

    /// Runs for `seconds` and records the step figures of every point from now on.
    std::vector<Step> run_step(double seconds) {
        std::vector<Step> s(kPoints);
        const double end = this->seconds() + seconds;
        while (this->seconds() < end) {
            scan();
            for (std::size_t p = 0; p < s.size(); ++p) {
                const int pv = reading(static_cast<int>(p));
                s[p].max = std::max(s[p].max, pv);
                if (std::abs(pv - kSp) > kBand) s[p].settled_s = this->seconds();
                if (this->seconds() > end - 600) {
                    s[p].low = std::min(s[p].low, pv);
                    s[p].high = std::max(s[p].high, pv);
                }
                s[p].last = pv;
            }
        }
        for (std::size_t p = 0; p < s.size(); ++p) s[p].in_zone_at_end = ((r(kWr) >> p) & 1u) != 0;
        return s;
    }

private:
    config::Config cfg_;
    daemon::Plc plc_;
};

std::string describe(const std::vector<Step>& s) {
    std::ostringstream o;
    for (std::size_t p = 0; p < s.size(); ++p) {
        o << "point " << p << ": overshoot " << s[p].overshoot() << " °C, outside ±5.0 °C last at "
          << s[p].settled_s << " s, last 10 min " << s[p].low / 10.0 << " to " << s[p].high / 10.0
          << " °C\n";
    }
    return o.str();
}

constexpr std::uint32_t kInZoneM = 400, kWarnM = 416;
constexpr double kSettled = 3000;  // simulated s by which the example's loops are in zone  // the
                                   // example's indicator relays

// The indicator relays the example's MOVs copy: M400+i is WR+0 bit i, M416+i WR+2 bit i.
std::uint16_t indicators(Loop& loop, std::uint32_t first) {
    std::uint16_t w = 0;
    for (std::uint32_t i = 0; i < 16; ++i)
        w = static_cast<std::uint16_t>(w | (loop.img().bit(Area::M, first + i) ? 1u << i : 0u));
    return w;
}

// Issue 14 point 2: the shipped example, R4005 untouched, settles within SP ± 5.0 °C by 50
// simulated minutes with ALM off.
TEST(ClosedLoop, DefaultYamlSettlesWithin5DegreesBy50MinutesWithR4005Default) {
    Loop loop(config_text());
    loop.start();
    loop.scan();
    EXPECT_EQ(loop.r(profiles::fbs::special::kPidTiming), 0x0102);
    const auto s = loop.run_step(3600);
    std::cout << describe(s);
    double worst = -1e9, latest = 0;
    for (int p = 0; p < kPoints; ++p) {
        const auto& x = s[static_cast<std::size_t>(p)];
        SCOPED_TRACE("point " + std::to_string(p));
        // The manual's default gains, given on the first execution (PR was 0).
        EXPECT_EQ(loop.r(120 + static_cast<std::uint32_t>(p)), 110);
        EXPECT_EQ(loop.r(130 + static_cast<std::uint32_t>(p)), 17);
        EXPECT_EQ(loop.r(140 + static_cast<std::uint32_t>(p)), 50);
        // Inside ±5.0 °C from 50 minutes on (the last 10 of the 60 minutes run).
        EXPECT_LE(x.settled_s, 3000.0);
        EXPECT_TRUE(x.in_zone_at_end);
        EXPECT_NEAR(x.last, kSp, kBand);
        EXPECT_GE(x.overshoot(), 0.0);  // it does reach SP
        EXPECT_LT(x.overshoot(), 5.0);  // and never leaves the zone from above
        worst = std::max(worst, x.overshoot());
        latest = std::max(latest, x.settled_s);
    }
    std::cout << "largest overshoot " << worst << " °C, all within ±5.0 °C from " << latest
              << " s\n";
    RecordProperty("largest_overshoot_0.1C", static_cast<int>(std::lround(worst * 10)));
    RecordProperty("settled_s", static_cast<int>(std::lround(latest)));
    EXPECT_FALSE(loop.img().bit(Area::M, kAlm));  // all in zone, no warning
    EXPECT_EQ(loop.r(kWr + 2), 0);
    EXPECT_EQ(loop.r(kWr + 4), 0x0204);  // in effect: PWM 2 s, solution 4 s
    // The example's indicators follow WR+0 / WR+2.
    EXPECT_EQ(indicators(loop, kInZoneM), 0x03FF);
    EXPECT_EQ(indicators(loop, kWarnM), 0);
}

TEST(ClosedLoop, HeaterOpenWarningSetsAfterR4007SecondsAndClearsWhenHeatingResumes) {
    // A plant fault: channel 3's heater circuit opens (u = 0). Its output goes to full scale and
    // the point leaves its zone; 600 s (R4007) of that sets bit 3 of WR+2.
    constexpr int p = 3;
    constexpr std::uint32_t bit = 1u << p;
    Loop loop(config_text());
    loop.start();
    loop.run_step(kSettled);
    ASSERT_EQ(loop.r(kWr) & 0x3FF, 0x3FF);
    plant::Faults f;
    f.heater_open = true;
    loop.plant().set_faults(p, f);
    const int threshold = (90 * 16383 + 99) / 100;  // R4006 = 90 %: OR ≥ 14745
    auto condition = [&] { return loop.r(kOr + p) >= threshold && (loop.r(kWr) & bit) == 0; };
    double since = -1;
    double set_at = -1;
    while (loop.seconds() < kSettled + 1200 && set_at < 0) {
        loop.scan();
        if (condition()) {
            if (since < 0) since = loop.seconds() - 0.01;  // the scan that just ran
        } else {
            since = -1;
        }
        if (loop.r(kWr + 2) & bit) set_at = loop.seconds() - 0.01;
    }
    ASSERT_GE(since, 0.0) << "output never went high out of zone";
    ASSERT_GE(set_at, 0.0) << "no heater-open warning";
    std::cout << "heater open: condition from " << since << " s, warning at " << set_at << " s\n";
    EXPECT_NEAR(set_at - since, 600.0, 0.011);  // R4007 default, to the scan
    EXPECT_EQ(loop.r(kWr + 2), bit);            // only that point
    EXPECT_EQ(loop.r(kWr + 7), bit);            // cause: heater open
    EXPECT_EQ(loop.r(kWr + 5), 0);
    EXPECT_TRUE(loop.img().bit(Area::M, kAlm));
    EXPECT_LT(loop.plant().true_temperature(p), 120.0);  // cooled towards ambient meanwhile
    EXPECT_EQ(indicators(loop, kWarnM), bit);            // M416 + 3, the example's indicator

    // Repaired: the warning holds while the condition holds, and clears the scan it stops
    // holding (in zone again, or output below 90 %).
    loop.plant().set_faults(p, plant::Faults{});
    bool cleared = false;
    while (loop.seconds() < set_at + 900 && !cleared) {
        loop.scan();
        const bool warn = (loop.r(kWr + 2) & bit) != 0;
        ASSERT_EQ(warn, condition()) << "at " << loop.seconds() << " s";
        cleared = !warn;
    }
    EXPECT_TRUE(cleared);
    const auto s = loop.run_step(1200);
    EXPECT_TRUE(s[p].in_zone_at_end);
    EXPECT_EQ(loop.r(kWr + 2), 0);
    EXPECT_FALSE(loop.img().bit(Area::M, kAlm));
}

TEST(ClosedLoop, OverTemperatureWarningAfter10ScansAtR4008AndClearsBelowIt) {
    // A shorted heater (u = 1) on channel 5 drives it towards 425 °C, past R4008, set to
    // 170.0 °C (within its 100–65535 range) so the slow plant gets there in minutes.
    constexpr int p = 5;
    constexpr std::uint32_t bit = 1u << p;
    constexpr int kLimit = 1700;
    Loop loop(config_text("  R4008: 1700\n"));
    loop.start();
    loop.run_step(kSettled);
    plant::Faults f;
    f.heater_shorted = true;
    loop.plant().set_faults(p, f);
    int scans_at_limit = 0;
    bool set = false;
    while (loop.seconds() < kSettled + 900 && !set) {
        loop.scan();
        scans_at_limit = loop.reading(p) >= kLimit ? scans_at_limit + 1 : 0;
        set = (loop.r(kWr + 2) & bit) != 0;
        if (!set) {
            ASSERT_LT(scans_at_limit, 10);
        }
    }
    ASSERT_TRUE(set) << "no over-temperature warning";
    EXPECT_EQ(scans_at_limit, 10);  // the 10th consecutive scan at or above R4008
    EXPECT_EQ(loop.r(kWr + 5), bit);
    EXPECT_EQ(loop.r(kWr + 7), 0);
    EXPECT_EQ(loop.r(kOr + p), 0);  // the PID itself has long turned the output off
    EXPECT_TRUE(loop.img().bit(Area::M, kAlm));
    EXPECT_EQ(indicators(loop, kWarnM), bit);  // M416 + 5, the example's indicator

    // Repaired: cools; the warning holds while the reading is at or above R4008 and clears the
    // scan it drops below.
    loop.plant().set_faults(p, plant::Faults{});
    bool cleared = false;
    while (loop.seconds() < kSettled + 2400 && !cleared) {
        loop.scan();
        const bool warn = (loop.r(kWr + 2) & bit) != 0;
        ASSERT_EQ(warn, loop.reading(p) >= kLimit) << "at " << loop.seconds() << " s";
        cleared = !warn;
    }
    EXPECT_TRUE(cleared);
    EXPECT_EQ(indicators(loop, kWarnM), 0);
    const auto s = loop.run_step(1200);
    EXPECT_TRUE(s[p].in_zone_at_end);
    EXPECT_FALSE(loop.img().bit(Area::M, kAlm));
}

}  // namespace
}  // namespace plcemu
