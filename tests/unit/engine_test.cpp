// Scan engine (docs/profile-fbs.md, Scan cycle and special registers) on virtual time: scan period,
// special relays M1920-M1926, special registers R4049, R4055, R4057, R4128-R4138, R4167 and the
// power-up defaults of R4005-R4013.

#include <gtest/gtest.h>

#include <chrono>
#include <memory>
#include <string>
#include <vector>

#include "profiles/fbs/specials.hpp"
#include "support/profiles.hpp"
#include "plcemu/engine/engine.hpp"
#include "profiles/fbs/special_registers.hpp"
#include "plcemu/image/image.hpp"

namespace plcemu::engine {
namespace {

using image::Area;
using std::chrono::milliseconds;
using std::chrono::seconds;

// Records what the program sees during each scan.
class Probe final : public Instruction {
public:
    explicit Probe(std::vector<std::string>& log, std::string name = "probe")
        : log_(log),
          name_(std::move(name)) {}
    void execute(ScanContext& ctx) noexcept override {
        log_.push_back(name_);
        first.push_back(ctx.first_scan);
        m1924.push_back(ctx.image.bit(Area::M, profiles::fbs::special::kFirstScan));
        now.push_back(ctx.now);
        dt.push_back(ctx.dt);
        scan.push_back(ctx.scan);
    }
    std::string_view mnemonic() const noexcept override { return "PROBE"; }

    std::vector<bool> first, m1924;
    std::vector<Duration> now, dt;
    std::vector<std::uint64_t> scan;

private:
    std::vector<std::string>& log_;
    std::string name_;
};

class Recorder final : public Subsystem {
public:
    Recorder(std::vector<std::string>& log, std::string name)
        : log_(log),
          name_(std::move(name)) {}
    void inputs(ScanContext&) noexcept override { log_.push_back(name_ + ".inputs"); }
    void outputs(ScanContext&) noexcept override { log_.push_back(name_ + ".outputs"); }

private:
    std::vector<std::string>& log_;
    std::string name_;
};

// An engine with a probe program that logs each scan (kept here, not a testing::PlcRig: the
// probe is this test's own instruction).
struct Rig {
    explicit Rig(int scan_ms = 10, std::uint8_t station = 1, std::uint16_t model = 0x0118) {
        EngineOptions o;
        o.scan_period = milliseconds(scan_ms);
        o.station = station;
        Program p;
        auto probe_ptr = std::make_unique<Probe>(log);
        probe = probe_ptr.get();
        p.push_back(std::move(probe_ptr));
        engine =
            std::make_unique<Engine>(img, o, std::move(p), profiles::fbs::make_specials(model));
        engine->power_up();
    }
    std::uint16_t r(std::uint32_t i) const { return img.word(Area::R, i); }
    bool m(std::uint32_t i) const { return img.bit(Area::M, i); }

    image::Image img{testing::fbs_layout()};
    std::vector<std::string> log;
    Probe* probe = nullptr;
    std::unique_ptr<Engine> engine;
};

// docs/profile-fbs.md, Scan cycle and special registers: fixed period scan_ms; virtual time runs N
// scans at once, one period apart.
TEST(Engine, RunsScansAtTheFixedPeriod) {
    Rig rig(10);
    rig.engine->run_scans(5);
    EXPECT_EQ(rig.engine->scans(), 5u);
    EXPECT_EQ(rig.engine->now(), milliseconds(40));
    EXPECT_EQ(rig.probe->now,
              (std::vector<Duration>{milliseconds(0), milliseconds(10), milliseconds(20),
                                     milliseconds(30), milliseconds(40)}));
    for (auto d : rig.probe->dt) EXPECT_EQ(d, milliseconds(10));
    EXPECT_EQ(rig.probe->scan, (std::vector<std::uint64_t>{0, 1, 2, 3, 4}));
    // One hour of simulated time in one call.
    rig.engine->run_scans(360000);
    EXPECT_EQ(rig.engine->now(), seconds(3600) + milliseconds(40));
}

// docs/profile-fbs.md, Scan cycle and special registers: each scan runs inputs, the program in
// order, outputs (reverse order).
TEST(Engine, ScanOrderInputsProgramOutputs) {
    image::Image img{testing::fbs_layout()};
    std::vector<std::string> log;
    Program p;
    p.push_back(std::make_unique<Probe>(log, "first"));
    p.push_back(std::make_unique<Probe>(log, "second"));
    Engine e(img, {}, std::move(p));
    e.add_subsystem(std::make_unique<Recorder>(log, "plant"));
    e.add_subsystem(std::make_unique<Recorder>(log, "temperature"));
    e.power_up();
    e.run_scans(1);
    EXPECT_EQ(log, (std::vector<std::string>{"plant.inputs", "temperature.inputs", "first",
                                             "second", "temperature.outputs", "plant.outputs"}));
}

// docs/profile-fbs.md, Scan cycle and special registers: M1924 is the first-scan pulse: ON during
// the first scan only, for the program too.
TEST(Engine, M1924FirstScanOnly) {
    Rig rig;
    rig.engine->run_scans(1);
    EXPECT_TRUE(rig.m(1924));
    rig.engine->run_scans(1);
    EXPECT_FALSE(rig.m(1924));
    rig.engine->run_scans(10);
    EXPECT_FALSE(rig.m(1924));
    ASSERT_GE(rig.probe->m1924.size(), 3u);
    EXPECT_TRUE(rig.probe->m1924[0]);
    EXPECT_TRUE(rig.probe->first[0]);
    EXPECT_FALSE(rig.probe->m1924[1]);
    EXPECT_FALSE(rig.probe->first[1]);
    // A new power-up gives a new first scan.
    rig.engine->power_up();
    rig.engine->run_scans(1);
    EXPECT_TRUE(rig.m(1924));
}

// docs/profile-fbs.md, Scan cycle and special registers: M1926 RUN = 1.
TEST(Engine, M1926RunIsOn) {
    Rig rig;
    rig.engine->run_scans(1);
    EXPECT_TRUE(rig.m(1926));
    rig.img.set_bit(Area::M, 1926, false);  // whatever happens between scans
    rig.engine->run_scans(1);
    EXPECT_TRUE(rig.m(1926));
}

// A program that drives Y0 and M5 ON every scan, and copies X0 to M6.
class Driver final : public Instruction {
public:
    void execute(ScanContext& ctx) noexcept override {
        ctx.image.set_bit(Area::Y, 0, true);
        ctx.image.set_bit(Area::M, 5, true);
        ctx.image.set_bit(Area::M, 6, ctx.image.bit(Area::X, 0));
        ++runs;
    }
    std::string_view mnemonic() const noexcept override { return "DRIVE"; }
    int runs = 0;
};

// An I/O refresh that drives X0 ON every scan.
class InputsOn final : public Subsystem {
public:
    void inputs(ScanContext& ctx) noexcept override { ctx.image.set_bit(Area::X, 0, true); }
};

struct DriverRig {
    DriverRig() {
        Program p;
        auto d = std::make_unique<Driver>();
        driver = d.get();
        p.push_back(std::move(d));
        engine = std::make_unique<Engine>(img, EngineOptions{}, std::move(p),
                                          profiles::fbs::make_specials(0x0118));
        engine->add_subsystem(std::make_unique<InputsOn>());
        engine->power_up();
    }
    image::Image img{testing::fbs_layout()};
    Driver* driver = nullptr;
    std::unique_ptr<Engine> engine;
};

// docs/profile-fbs.md, "FATEK protocol" (command 41): STOP runs no instruction, turns the
// outputs off at once and keeps them off, shows M1926 OFF; RUN resumes with a first scan (M1924).
TEST(Engine, StopRunsNoInstructionAndHoldsOutputsOff) {
    DriverRig rig;
    rig.engine->run_scans(2);
    ASSERT_TRUE(rig.img.bit(Area::Y, 0));
    ASSERT_EQ(rig.driver->runs, 2);
    rig.engine->set_running(false);
    EXPECT_FALSE(rig.engine->running());
    EXPECT_FALSE(rig.img.bit(Area::Y, 0));     // off at once, before the next scan
    EXPECT_FALSE(rig.img.bit(Area::M, 1926));  // RUN relay shows STOP at once
    rig.img.set_bit(Area::Y, 3, true);         // a master's write in STOP
    rig.engine->run_scans(3);
    EXPECT_EQ(rig.driver->runs, 2);
    EXPECT_FALSE(rig.img.bit(Area::Y, 3));
    EXPECT_FALSE(rig.img.bit(Area::M, 1926));
    EXPECT_TRUE(rig.img.bit(Area::M, 5));  // internal relays keep their values
    EXPECT_TRUE(rig.img.bit(Area::X, 0));  // inputs are still refreshed
    rig.engine->run_scans(1);
    EXPECT_FALSE(rig.img.bit(Area::M, 1924));
    rig.engine->set_running(true);
    rig.engine->run_scans(1);
    EXPECT_EQ(rig.driver->runs, 3);
    EXPECT_TRUE(rig.img.bit(Area::Y, 0));
    EXPECT_TRUE(rig.img.bit(Area::M, 1926));
    EXPECT_TRUE(rig.img.bit(Area::M, 1924));  // STOP→RUN: a first scan
    rig.engine->run_scans(1);
    EXPECT_FALSE(rig.img.bit(Area::M, 1924));
}

// docs/profile-fbs.md, "FATEK protocol" (command 42): a disabled discrete keeps what a master
// wrote: the I/O refresh cannot change a disabled input, the program cannot change a disabled
// output or relay, and the program reads the input as the master left it.
TEST(Engine, DisabledDiscretesKeepWhatAMasterWrote) {
    DriverRig rig;
    Holds& h = rig.engine->holds();
    EXPECT_TRUE(h.set(Area::X, 0, true));
    EXPECT_TRUE(h.set(Area::Y, 0, true));
    EXPECT_TRUE(h.set(Area::M, 5, true));
    EXPECT_FALSE(h.set(Area::X, 100000, true));  // no such discrete
    EXPECT_TRUE(h.held(Area::Y, 0));
    EXPECT_FALSE(h.held(Area::Y, 1));
    rig.engine->run_scans(3);
    EXPECT_FALSE(rig.img.bit(Area::X, 0));
    EXPECT_FALSE(rig.img.bit(Area::Y, 0));
    EXPECT_FALSE(rig.img.bit(Area::M, 5));
    EXPECT_FALSE(rig.img.bit(Area::M, 6));  // the program saw X0 OFF
    rig.img.set_bit(Area::Y, 0, true);      // the master sets it: kept
    rig.engine->run_scans(2);
    EXPECT_TRUE(rig.img.bit(Area::Y, 0));
    // Kept across STOP too: a disabled output stays as the master left it.
    rig.engine->set_running(false);
    rig.engine->run_scans(1);
    EXPECT_TRUE(rig.img.bit(Area::Y, 0));
    rig.engine->set_running(true);
    // Enabled again: the next scan drives them as the program and the inputs say.
    h.set(Area::X, 0, false);
    h.set(Area::M, 5, false);
    EXPECT_TRUE(h.set(Area::Y, 0, false));
    EXPECT_TRUE(h.empty());
    rig.engine->run_scans(1);
    EXPECT_TRUE(rig.img.bit(Area::X, 0));
    EXPECT_TRUE(rig.img.bit(Area::M, 5));
    EXPECT_TRUE(rig.img.bit(Area::M, 6));
}

// Samples an M relay after each of `n` scans.
std::vector<bool> sample(Rig& rig, std::uint32_t relay, int n) {
    std::vector<bool> v;
    for (int i = 0; i < n; ++i) {
        rig.engine->run_scans(1);
        v.push_back(rig.m(relay));
    }
    return v;
}

// Number of OFF->ON and ON->OFF changes, and the ON count.
struct Wave {
    int changes = 0;
    int on = 0;
};
Wave wave(const std::vector<bool>& v) {
    Wave w;
    for (std::size_t i = 0; i < v.size(); ++i) {
        w.on += v[i];
        if (i > 0 && v[i] != v[i - 1]) ++w.changes;
    }
    return w;
}

// docs/profile-fbs.md, Scan cycle and special registers: M1920/M1921/M1922/M1923 are
// 0.01 s / 0.1 s / 1 s / 60 s square waves of the simulated clock.
TEST(Engine, ClockRelaysAreSquareWaves) {
    Rig rig(1);                                  // 1 ms scans: every clock is resolved
    const auto m1920 = sample(rig, 1920, 1000);  // one second
    EXPECT_EQ(wave(m1920).changes, 199);         // 100 periods of 10 ms
    EXPECT_EQ(wave(m1920).on, 500);
    // ON for the first half of each period: 5 ON, 5 OFF.
    EXPECT_EQ(
        std::vector<bool>(m1920.begin(), m1920.begin() + 11),
        (std::vector<bool>{true, true, true, true, true, false, false, false, false, false, true}));

    Rig r2(1);
    const auto m1921 = sample(r2, 1921, 1000);
    EXPECT_EQ(wave(m1921).changes, 19);
    EXPECT_EQ(wave(m1921).on, 500);

    Rig r3(10);
    const auto m1922 = sample(r3, 1922, 1000);  // ten seconds
    EXPECT_EQ(wave(m1922).changes, 19);
    EXPECT_EQ(wave(m1922).on, 500);
    EXPECT_TRUE(m1922[0]);
    EXPECT_TRUE(m1922[49]);
    EXPECT_FALSE(m1922[50]);

    Rig r4(100);
    const auto m1923 = sample(r4, 1923, 6000);  // ten minutes
    EXPECT_EQ(wave(m1923).changes, 19);
    EXPECT_EQ(wave(m1923).on, 3000);
    EXPECT_TRUE(m1923[299]);
    EXPECT_FALSE(m1923[300]);
}

// Decision: a clock faster than the scan can show toggles on every scan (M1920 with the
// default 10 ms scan), instead of aliasing to a constant.
TEST(Engine, ClockFasterThanTheScanTogglesEveryScan) {
    Rig rig(10);
    const auto m1920 = sample(rig, 1920, 100);
    EXPECT_EQ(wave(m1920).changes, 99);
    EXPECT_EQ(wave(m1920).on, 50);
    // M1921 (0.1 s) at 10 ms is resolved: 5 scans ON, 5 OFF.
    Rig r2(10);
    const auto m1921 = sample(r2, 1921, 100);
    EXPECT_EQ(wave(m1921).changes, 19);
    EXPECT_EQ(wave(m1921).on, 50);
    // Scan 50 ms = half of M1921's period: alternates every scan, evenly.
    Rig r3(50);
    EXPECT_EQ(wave(sample(r3, 1921, 10)).changes, 9);
}

// docs/profile-fbs.md, Scan cycle and special registers: R4136/R4137/R4138 current/maximum/minimum
// scan time in ms (Decision: the simulated interval between scan starts).
TEST(Engine, ScanTimeRegisters) {
    Rig rig(10);
    rig.engine->run_scans(3);
    EXPECT_EQ(rig.r(4136), 10);
    EXPECT_EQ(rig.r(4137), 10);
    EXPECT_EQ(rig.r(4138), 10);
    const Duration t = rig.engine->now();
    rig.engine->step(t + milliseconds(25), {});
    EXPECT_EQ(rig.r(4136), 25);
    EXPECT_EQ(rig.r(4137), 25);
    EXPECT_EQ(rig.r(4138), 10);
    rig.engine->step(t + milliseconds(29), {});
    EXPECT_EQ(rig.r(4136), 4);
    EXPECT_EQ(rig.r(4137), 25);
    EXPECT_EQ(rig.r(4138), 4);
    // A Modbus-side write between scans does not stick.
    rig.img.set_word(Area::R, 4136, 999);
    rig.engine->step(t + milliseconds(39), {});
    EXPECT_EQ(rig.r(4136), 10);
    // Longer than 65535 ms: saturates.
    rig.engine->step(t + seconds(100), {});
    EXPECT_EQ(rig.r(4136), 0xFFFF);
    EXPECT_EQ(rig.r(4137), 0xFFFF);
}

// A power-up starts the simulated time and the scan-time registers over: the next scan is at
// time 0, and the maximum and minimum scan times count from it.
TEST(Engine, PowerUpStartsTimeAndScanTimesOver) {
    Rig rig(10);
    rig.engine->run_scans(3);
    rig.engine->step(rig.engine->now() + milliseconds(25), {});
    ASSERT_EQ(rig.r(4137), 25);
    rig.engine->power_up();
    EXPECT_EQ(rig.engine->now(), Duration{0});
    EXPECT_EQ(rig.engine->scans(), 0u);
    rig.engine->run_scans(1);
    EXPECT_EQ(rig.engine->now(), Duration{0});
    EXPECT_EQ(rig.r(4136), 10);
    EXPECT_EQ(rig.r(4137), 10);
    EXPECT_EQ(rig.r(4138), 10);
}

// docs/profile-fbs.md, Scan cycle and special registers: R4128-R4134 calendar (second, minute,
// hour, day, month, year, weekday) from the calendar passed in (the engine reads no clock).
TEST(Engine, CalendarRegistersComeFromThePassedCalendar) {
    Rig rig;
    rig.engine->run_scans(1, Calendar{58, 59, 23, 31, 12, 2026, 4});
    EXPECT_EQ(rig.r(4128), 58);
    EXPECT_EQ(rig.r(4129), 59);
    EXPECT_EQ(rig.r(4130), 23);
    EXPECT_EQ(rig.r(4131), 31);
    EXPECT_EQ(rig.r(4132), 12);
    EXPECT_EQ(rig.r(4133), 26);  // two digits
    EXPECT_EQ(rig.r(4134), 4);
    rig.engine->run_scans(1, Calendar{0, 0, 0, 1, 1, 2027, 5});
    EXPECT_EQ(rig.r(4128), 0);
    EXPECT_EQ(rig.r(4131), 1);
    EXPECT_EQ(rig.r(4133), 27);
    EXPECT_EQ(rig.r(4134), 5);
}

// docs/profile-fbs.md, Scan cycle and special registers: R4055 low byte is the station; a master
// changes it by writing 55h in the high byte. Anything else written there is put back at the next
// scan.
TEST(Engine, R4055StationChangeVia55xx) {
    Rig rig(10, 3);
    EXPECT_EQ(rig.r(4055), 3);  // initialised from the config at power-up
    EXPECT_EQ(rig.engine->station(), 3);
    rig.engine->run_scans(1);
    EXPECT_EQ(rig.r(4055), 3);

    rig.img.set_word(Area::R, 4055, 0x5511);
    rig.engine->run_scans(1);
    EXPECT_EQ(rig.engine->station(), 0x11);
    EXPECT_EQ(rig.r(4055), 0x11);

    for (std::uint16_t v : std::vector<std::uint16_t>{0x0007, 0x1234, 0x5500, 0x55FF, 0x5607}) {
        rig.img.set_word(Area::R, 4055, v);
        rig.engine->run_scans(1);
        EXPECT_EQ(rig.engine->station(), 0x11) << std::hex << v;
        EXPECT_EQ(rig.r(4055), 0x11) << std::hex << v;
    }
    rig.img.set_word(Area::R, 4055, 0x55FE);
    rig.engine->run_scans(1);
    EXPECT_EQ(rig.engine->station(), 254);
    rig.img.set_word(Area::R, 4055, 0x5501);
    rig.engine->run_scans(1);
    EXPECT_EQ(rig.engine->station(), 1);
}

// A station a master asks for through R4055 is a request the scan reports, not a change it makes:
// whoever knows the unit IDs on the PLC's listeners grants it after the scan, or not
// (docs/configuration.md, "Sharing a listener"); until then R4055 shows the station in force.
TEST(Engine, R4055IsARequestTheScanReportsAndSetStationGrants) {
    Rig rig(10, 1);
    rig.engine->run_scans(1);
    rig.img.set_word(Area::R, 4055, 0x5505);
    const auto wanted = rig.engine->step(rig.engine->now() + milliseconds(10), {});
    ASSERT_TRUE(wanted.has_value());
    EXPECT_EQ(*wanted, 5);
    EXPECT_EQ(rig.engine->station(), 1);
    EXPECT_EQ(rig.r(4055), 1);
    // Refused (not granted): the next scan reports nothing new and the station stays.
    EXPECT_FALSE(rig.engine->step(rig.engine->now() + milliseconds(10), {}).has_value());
    EXPECT_EQ(rig.engine->station(), 1);
    EXPECT_EQ(rig.r(4055), 1);

    rig.img.set_word(Area::R, 4055, 0x5505);
    EXPECT_EQ(rig.engine->step(rig.engine->now() + milliseconds(10), {}).value_or(0), 5);
    rig.engine->set_station(5);
    // Seen at once, before any further scan: a read right after the scan that asked.
    EXPECT_EQ(rig.engine->station(), 5);
    EXPECT_EQ(rig.r(4055), 5);
    EXPECT_FALSE(rig.engine->step(rig.engine->now() + milliseconds(10), {}).has_value());
    EXPECT_EQ(rig.r(4055), 5);
    // Its own station again is no request; anything but 55xxh with 1-254 is none either.
    for (std::uint16_t v : std::vector<std::uint16_t>{0x5505, 0x0007, 0x5500, 0x55FF, 0x5607}) {
        rig.img.set_word(Area::R, 4055, v);
        EXPECT_FALSE(rig.engine->step(rig.engine->now() + milliseconds(10), {}).has_value())
            << std::hex << v;
        EXPECT_EQ(rig.r(4055), 5) << std::hex << v;
    }
}

// A family without a station register (as the VB) reports no request, and a station granted
// anyway changes no register.
TEST(Engine, ScansWithoutSpecialsReportNoStationRequest) {
    image::Image img{testing::fbs_layout()};
    Engine e(img, {}, {});
    e.power_up();
    img.set_word(Area::R, 4055, 0x5505);
    EXPECT_FALSE(e.step(Duration{0}, {}).has_value());
    EXPECT_EQ(e.station(), 1);
    e.set_station(9);
    EXPECT_EQ(e.station(), 9);
    EXPECT_EQ(img.word(Area::R, 4055), 0x5505);  // no register of the family's: untouched
}

// docs/profile-fbs.md, Scan cycle and special registers: R4057 power-up counter (retentive): one
// more at every power-up.
TEST(Engine, R4057CountsPowerUps) {
    image::Image img{testing::fbs_layout()};
    img.set_word(Area::R, 4057, 41);  // retained from earlier runs
    Engine e(img, {}, {}, profiles::fbs::make_specials(0x0118));
    e.power_up();
    EXPECT_EQ(img.word(Area::R, 4057), 42);
    e.run_scans(100);
    EXPECT_EQ(img.word(Area::R, 4057), 42);  // not per scan
    e.power_up();
    EXPECT_EQ(img.word(Area::R, 4057), 43);
    // It is in the retentive ranges of the layout.
    bool retentive = false;
    for (const auto& r : img.layout().retentive) {
        retentive = retentive || r.contains({Area::R, 4057, 1});
    }
    EXPECT_TRUE(retentive);
}

// docs/profile-fbs.md, Scan cycle and special registers: R4167 model code, R4049 CPU status
// 0 = running normally; both kept every scan.
TEST(Engine, R4167ModelCodeAndR4049Status) {
    Rig rig(10, 1, 0x023C);
    EXPECT_EQ(rig.r(4167), 0x023C);
    EXPECT_EQ(rig.r(4049), 0);
    rig.img.set_word(Area::R, 4167, 1);
    rig.img.set_word(Area::R, 4049, 7);
    rig.engine->run_scans(1);
    EXPECT_EQ(rig.r(4167), 0x023C);
    EXPECT_EQ(rig.r(4049), 0);
}

// FBs manual §21.7 and §21.3.3: defaults of R4005-R4008 and R4010-R4013 at power-up; R4009 (0 = °C)
// untouched.
TEST(Engine, PowerUpDefaultsOfR4005ToR4013) {
    Rig rig;
    EXPECT_EQ(rig.r(4005), 0x0102);
    EXPECT_EQ(rig.r(4006), 90);
    EXPECT_EQ(rig.r(4007), 600);
    EXPECT_EQ(rig.r(4008), 3500);
    EXPECT_EQ(rig.r(4009), 0);
    EXPECT_EQ(rig.r(4010), 0xFFFF);
    EXPECT_EQ(rig.r(4011), 0xFFFF);
    EXPECT_EQ(rig.r(4012), 0xFFFF);
    EXPECT_EQ(rig.r(4013), 0xFFFF);
    // They are only defaults: a master (or a preset) may change them and scans keep the value.
    rig.img.set_word(Area::R, 4005, 0x0303);
    rig.img.set_word(Area::R, 4012, 0x00FF);
    rig.engine->run_scans(10);
    EXPECT_EQ(rig.r(4005), 0x0303);
    EXPECT_EQ(rig.r(4012), 0x00FF);
}

// docs/profile-fbs.md, Scan cycle and special registers: time is injected: the scan at `now` sees
// exactly that time (no clock is read).
TEST(Engine, StepUsesThePassedTime) {
    Rig rig(10);
    rig.engine->step(seconds(7), {});
    rig.engine->step(seconds(7) + milliseconds(10), {});
    ASSERT_EQ(rig.probe->now.size(), 2u);
    EXPECT_EQ(rig.probe->now[0], seconds(7));
    EXPECT_EQ(rig.probe->dt[0], milliseconds(10));  // first scan: one period
    EXPECT_EQ(rig.probe->now[1], seconds(7) + milliseconds(10));
    EXPECT_EQ(rig.engine->now(), seconds(7) + milliseconds(10));
    rig.engine->run_scans(1);
    EXPECT_EQ(rig.engine->now(), seconds(7) + milliseconds(20));
}

}  // namespace
}  // namespace plcemu::engine
