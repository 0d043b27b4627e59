// Thermal plant (docs/simulator-and-plant.md, Thermal plant): first order plus dead time per
// channel, drives, faults, noise, and the determinism of whole runs (issue 3 item 5).

#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <functional>

#include "plcemu/daemon/plc.hpp"
#include "support/config_errors.hpp"
#include "support/profiles.hpp"
#include "plcemu/config/config.hpp"
#include "plcemu/daemon/plc.hpp"
#include "plcemu/engine/engine.hpp"
#include "plcemu/image/image.hpp"
#include "plcemu/plant/thermal_plant.hpp"
#include "support/wire.hpp"

namespace plcemu::plant {
namespace {

// The plant a PLC of `cfg` gets: its channels driven by the outputs the program declares.
std::unique_ptr<ThermalPlant> plant_of(const config::Config& cfg) {
    return std::make_unique<ThermalPlant>(
        daemon::plant_setup(cfg, engine::declarations_of(daemon::build_program(cfg))));
}

using image::Area;
using std::chrono::milliseconds;

// Runs a callback as the program, so a test can drive outputs scan by scan.
class Program final : public engine::Instruction {
public:
    explicit Program(std::function<void(engine::ScanContext&)> f)
        : f_(std::move(f)) {}
    void execute(engine::ScanContext& ctx) noexcept override { f_(ctx); }
    std::string_view mnemonic() const noexcept override { return "TEST"; }

private:
    std::function<void(engine::ScanContext&)> f_;
};

// An engine with one plant channel driven by a register (u = R200/16383) or by Y30. Kept here:
// the thermal model on its own, without a config.
struct Rig {
    explicit Rig(ChannelParams ch,
                 Drive::Kind kind = Drive::Kind::Register,
                 int scan_ms = 10,
                 std::function<void(engine::ScanContext&)> program = {})
        : image(testing::fbs_layout()) {
        engine::EngineOptions o;
        o.scan_period = milliseconds(scan_ms);
        engine::Program p;
        if (program) p.push_back(std::make_unique<Program>(std::move(program)));
        engine = std::make_unique<engine::Engine>(image, o, std::move(p));
        engine->power_up();
        PlantSetup setup;
        for (auto& c : setup.channels) c.params = ch;
        setup.channels[0].drive = kind == Drive::Kind::Register ? Drive{kind, {Area::R, 200, false}}
                                                                : Drive{kind, {Area::Y, 30, false}};
        auto pl = std::make_unique<ThermalPlant>(setup);
        plant = pl.get();
        engine->add_subsystem(std::move(pl));
    }
    void run_seconds(double s) {
        const auto n = static_cast<std::uint64_t>(
            std::llround(s * 1e9 / static_cast<double>(engine->scan_period().count())));
        engine->run_scans(n);
    }
    image::Image image;
    std::unique_ptr<engine::Engine> engine;
    ThermalPlant* plant = nullptr;
};

double seconds(engine::Duration d) { return std::chrono::duration<double>(d).count(); }

ChannelParams no_dead_time() {
    ChannelParams c;
    c.dead_time_s = 0;
    return c;
}

TEST(Plant, DefaultsAreTheDocumentedValues) {
    // docs/simulator-and-plant.md, Thermal plant: K 400 °C, τ 120 s, θ 5 s, 25 °C.
    ThermalPlant p(PlantSetup{});
    for (int c = 0; c < kChannels; ++c) {
        EXPECT_EQ(p.params(c).k_c, 400.0);
        EXPECT_EQ(p.params(c).tau_s, 120.0);
        EXPECT_EQ(p.params(c).dead_time_s, 5.0);
        EXPECT_EQ(p.params(c).ambient_c, 25.0);
        EXPECT_EQ(p.true_temperature(c), 25.0);
        EXPECT_EQ(p.drive(c).kind, Drive::Kind::None);
    }
}

TEST(Plant, FirstOrderStepFollowsTheAnalyticSolution) {
    // docs/simulator-and-plant.md, Thermal plant: dT/dt = (K·u − (T − T_amb))/τ; with u = 1
    // from t = 0, T = T_amb + K(1 − e^(−t/τ)).
    Rig rig(no_dead_time(), Drive::Kind::Register, 100);
    rig.image.set_word(Area::R, 200, 16383);
    rig.engine->run_scans(1);  // t = 0: the drive is latched
    for (double t : {10.0, 60.0, 120.0, 600.0}) {
        rig.run_seconds(t - seconds(rig.engine->now()));
        const double now = seconds(rig.engine->now());
        const double expected = 25.0 + 400.0 * (1.0 - std::exp(-now / 120.0));
        EXPECT_NEAR(rig.plant->true_temperature(0), expected, 1e-6) << "t = " << now;
    }
}

TEST(Plant, ExactDiscretisationIsStableForAnyScanPeriod) {
    // A scan much longer than τ must neither oscillate nor overshoot.
    ChannelParams c = no_dead_time();
    c.tau_s = 0.5;
    Rig rig(c, Drive::Kind::Register, 1000);
    rig.image.set_word(Area::R, 200, 16383);
    double prev = 25.0;
    for (int i = 0; i < 20; ++i) {
        rig.engine->run_scans(1);
        const double t = rig.plant->true_temperature(0);
        EXPECT_GE(t, prev - 1e-9);
        EXPECT_LE(t, 425.0 + 1e-9);
        prev = t;
    }
    EXPECT_NEAR(prev, 425.0, 1e-6);
}

TEST(Plant, SameResultWhateverTheScanPeriod) {
    // Exact integration: a 10 ms scan and a 500 ms scan reach the same temperature.
    Rig fine(no_dead_time(), Drive::Kind::Register, 10);
    Rig coarse(no_dead_time(), Drive::Kind::Register, 500);
    fine.image.set_word(Area::R, 200, 8192);
    coarse.image.set_word(Area::R, 200, 8192);
    fine.engine->run_scans(10001);  // both end at t = 100 s
    coarse.engine->run_scans(201);
    ASSERT_EQ(fine.engine->now(), coarse.engine->now());
    EXPECT_NEAR(fine.plant->true_temperature(0), coarse.plant->true_temperature(0), 1e-6);
}

TEST(Plant, DeadTimeDelaysTheResponseByTheta) {
    // docs/simulator-and-plant.md, Thermal plant: the response is delayed by θ.
    ChannelParams c;
    c.dead_time_s = 5.0;
    Rig rig(c);
    rig.image.set_word(Area::R, 200, 16383);
    rig.run_seconds(4.99);
    EXPECT_EQ(rig.plant->true_temperature(0), 25.0);
    rig.run_seconds(5.0);
    // About 5 s of heating: 400·(1 − e^(−5/120)) ≈ 16.3 °C.
    EXPECT_NEAR(rig.plant->true_temperature(0), 25.0 + 400.0 * (1 - std::exp(-5.0 / 120.0)), 0.2);
}

TEST(Plant, OutputRegisterDriveIsOrOver16383) {
    // docs/simulator-and-plant.md, Thermal plant: the heater driven by an analog output has
    // u = OR / 16383.
    Rig rig(no_dead_time(), Drive::Kind::Register, 100);
    rig.image.set_word(Area::R, 200, 4096);
    rig.run_seconds(2000);
    EXPECT_NEAR(rig.plant->true_temperature(0), 25.0 + 400.0 * 4096.0 / 16383.0, 0.01);
    EXPECT_NEAR(rig.plant->heater_power(0), 4096.0 / 16383.0, 1e-9);
    rig.image.set_word(Area::R, 200, 30000);  // beyond full scale: full power
    rig.run_seconds(1);
    EXPECT_NEAR(rig.plant->drive_now(0), 1.0, 1e-12);
}

TEST(Plant, PwmDutyOfTheYOutputIsTheAveragePower) {
    // docs/simulator-and-plant.md, Thermal plant: u is the duty of the Y output over time.
    // 25 % duty on a 2 s cycle.
    Rig rig(no_dead_time(), Drive::Kind::Output, 100, [](engine::ScanContext& ctx) {
        const auto ms = std::chrono::duration_cast<milliseconds>(ctx.now).count();
        ctx.image.set_bit(Area::Y, 30, ms % 2000 < 500);
    });
    rig.run_seconds(1500);
    // Ripple of a 2 s cycle through τ = 120 s is about ±1 °C.
    EXPECT_NEAR(rig.plant->true_temperature(0), 125.0, 1.5);
    EXPECT_NEAR(rig.plant->heater_power(0), 0.25, 0.002);
}

TEST(Plant, CoolingChannelsPullTemperatureDown) {
    // docs/simulator-and-plant.md, Thermal plant: cooling channels pull T down.
    ChannelParams c = no_dead_time();
    c.cooling = true;
    c.ambient_c = 80;
    c.k_c = 60;
    Rig rig(c, Drive::Kind::Register, 100);
    rig.image.set_word(Area::R, 200, 16383);
    rig.run_seconds(2000);
    EXPECT_NEAR(rig.plant->true_temperature(0), 20.0, 0.01);
}

TEST(Plant, HeaterOpenForcesZeroPower) {
    // docs/simulator-and-plant.md, Thermal plant, faults: heater open, u forced to 0.
    Rig rig(no_dead_time());
    rig.image.set_word(Area::R, 200, 16383);
    rig.plant->set_faults(0, {.heater_open = true});
    rig.run_seconds(100);
    EXPECT_EQ(rig.plant->true_temperature(0), 25.0);
    EXPECT_EQ(rig.plant->heater_power(0), 0.0);
    rig.plant->set_faults(0, {});
    rig.run_seconds(100);
    EXPECT_GT(rig.plant->true_temperature(0), 100.0);
}

TEST(Plant, HeaterShortedForcesFullPower) {
    // docs/simulator-and-plant.md, Thermal plant, faults: heater shorted, u forced to 1 whatever
    // the output.
    Rig rig(no_dead_time(), Drive::Kind::Register, 100);
    rig.image.set_word(Area::R, 200, 0);
    rig.plant->set_faults(0, {.heater_shorted = true});
    rig.run_seconds(2000);
    EXPECT_NEAR(rig.plant->true_temperature(0), 425.0, 0.01);
    EXPECT_NEAR(rig.plant->heater_power(0), 1.0, 1e-9);
}

TEST(Plant, SensorBrokenAndReadingFrozenFaults) {
    // docs/simulator-and-plant.md, Thermal plant, faults: sensor broken (no temperature), reading
    // frozen (stops changing).
    Rig rig(no_dead_time());
    rig.image.set_word(Area::R, 200, 16383);
    rig.run_seconds(10);
    const engine::SensorSample before = rig.plant->sense(0);
    EXPECT_FALSE(before.broken);
    EXPECT_EQ(before.celsius, rig.plant->true_temperature(0));
    rig.plant->set_faults(0, {.reading_frozen = true});
    rig.run_seconds(60);
    EXPECT_EQ(rig.plant->sense(0).celsius, before.celsius);
    EXPECT_GT(rig.plant->true_temperature(0), before.celsius + 50);  // the process goes on
    rig.plant->set_faults(0, {.sensor_broken = true});
    EXPECT_TRUE(rig.plant->sense(0).broken);
    rig.plant->set_faults(0, {});
    EXPECT_EQ(rig.plant->sense(0).celsius, rig.plant->true_temperature(0));
}

TEST(Plant, NoiseIsGaussianWithSigmaAndDeterministicPerSeed) {
    // docs/simulator-and-plant.md, Thermal plant, noise; issue 3 item 5: a fixed seed gives the
    // same samples.
    PlantSetup pc;
    for (auto& c : pc.channels) c.params.noise_c = 0.5;
    pc.seed = 42;
    ThermalPlant a(pc);
    ThermalPlant b(pc);
    pc.seed = 43;
    ThermalPlant other(pc);
    double sum = 0, sq = 0;
    int differ = 0;
    const int n = 20000;
    for (int i = 0; i < n; ++i) {
        const double x = a.sense(3).celsius - 25.0;
        EXPECT_EQ(x + 25.0, b.sense(3).celsius);
        differ += other.sense(3).celsius != x + 25.0 ? 1 : 0;
        sum += x;
        sq += x * x;
    }
    const double mean = sum / n;
    EXPECT_NEAR(mean, 0.0, 0.02);
    EXPECT_NEAR(std::sqrt(sq / n - mean * mean), 0.5, 0.02);
    EXPECT_GT(differ, n - 10);
}

TEST(Plant, DefaultDriveIsTheYOfTheTpctlPointOfTheChannel) {
    // The channel Sn + i is heated by Yn + i; an explicit plant drive wins; the first TPCTL wins.
    const auto cfg = config::parse_config(R"(
profile: fbs
plant:
  channels:
    5: {drive: R200}
program:
  - TPCTL: {en: M0, hc: 1, md: 0, sn: 2, zn: 4, yn: Y30, sv: R100, os: R110, pr: R120,
            ir: R130, dr: R140, or: R200, wr: R300, err: M100, alm: M101}
  - TPCTL: {en: M0, hc: 1, md: 0, sn: 4, zn: 2, yn: Y50, sv: R400, os: R410, pr: R420,
            ir: R430, dr: R440, or: R450, wr: R460, err: M102, alm: M103}
)",
                                          "drives.yaml");
    const auto p = plant_of(cfg);
    EXPECT_EQ(p->drive(1).kind, Drive::Kind::None);
    EXPECT_EQ(p->drive(2), (Drive{Drive::Kind::Output, {Area::Y, 30, false}}));
    EXPECT_EQ(p->drive(4), (Drive{Drive::Kind::Output, {Area::Y, 32, false}}));
    EXPECT_EQ(p->drive(5), (Drive{Drive::Kind::Register, {Area::R, 200, false}}));
    EXPECT_EQ(p->drive(6).kind, Drive::Kind::None);
}

TEST(Plant, PerChannelParametersAndFaultsFromConfig) {
    const auto cfg = config::parse_config(R"(
profile: fbs
plant:
  seed: 9
  defaults: {ambient: 20, k: 300}
  channels:
    3: {tau: 60, dead_time: 2, noise: 0.1, cooling: true, faults: {heater_open: true}}
)",
                                          "params.yaml");
    const auto p = plant_of(cfg);
    EXPECT_EQ(p->params(0), (ChannelParams{20, 300, 120, 5, 0, false}));
    EXPECT_EQ(p->params(3), (ChannelParams{20, 300, 60, 2, 0.1, true}));
    EXPECT_TRUE(p->faults(3).heater_open);
    EXPECT_FALSE(p->faults(2).heater_open);
    EXPECT_EQ(p->true_temperature(3), 20.0);
}

// docs/simulator-and-plant.md, "Lead resistance": plant.channels.N.lead_resistance (Ω, 0–100)
// comes with every sample of the channel, broken or frozen too.
TEST(Plant, LeadResistanceComesWithEachSample) {
    const auto cfg = config::parse_config(R"(
profile: fbs
plant:
  channels:
    2: {lead_resistance: 1.5, faults: {sensor_broken: true}}
    4: {lead_resistance: 0.25}
)",
                                          "lead.yaml");
    const auto p = plant_of(cfg);
    EXPECT_EQ(p->params(2).lead_ohm, 1.5);
    EXPECT_EQ(p->sense(2).lead_ohm, 1.5);
    EXPECT_TRUE(p->sense(2).broken);
    EXPECT_EQ(p->sense(4).lead_ohm, 0.25);
    EXPECT_EQ(p->sense(0).lead_ohm, 0.0);
    ChannelParams c = p->params(4);
    c.lead_ohm = 500.0;  // at most 100 Ω
    p->set_params(4, c);
    EXPECT_EQ(p->sense(4).lead_ohm, 100.0);
    testing::expect_config_error(testing::config_failure([] {
                                     config::parse_config(
                                         "profile: fbs\nplant:\n  channels:\n"
                                         "    1: {lead_resistance: 101}\n",
                                         "lead.yaml");
                                 }),
                                 "lead.yaml", 4, 26, "lead_resistance");
}

// docs/simulator-and-plant.md, "Reload": the process temperatures carry over to the new PLC
// through the Plant interface (state(), restore()) as the daemon's reload does; parameters and
// faults are the new configuration's.
TEST(Plant, ReloadCarriesTheProcessAndTheLastReadingThroughTheInterface) {
    const auto before = config::parse_config(R"(
profile: fbs
plant:
  channels:
    0: {noise: 0.5, dead_time: 0, faults: {heater_shorted: true}}
)",
                                             "before.yaml");
    daemon::Plc old(before);
    old.engine().run_scans(6000);  // 60 s at full power
    plant::Plant& hot = old.plant();
    const double reading = hot.sense(0).celsius;
    ASSERT_GT(hot.true_temperature(0), 100.0);
    ASSERT_NE(reading, hot.true_temperature(0));  // the noise: the two are told apart below

    const auto after = config::parse_config(R"(
profile: fbs
plant:
  channels:
    0: {ambient: 30, faults: {reading_frozen: true}}
)",
                                            "after.yaml");
    daemon::Plc next(after);
    plant::Plant& fresh = next.plant();
    EXPECT_EQ(fresh.true_temperature(0), 30.0);  // as built: at its ambient
    fresh.restore(hot.state());
    EXPECT_EQ(fresh.true_temperature(0), hot.true_temperature(0));
    EXPECT_EQ(fresh.true_temperature(1), 25.0);
    // The frozen sensor holds the last value the old plant's sensor gave.
    EXPECT_EQ(fresh.sense(0).celsius, reading);
    EXPECT_EQ(fresh.params(0).ambient_c, 30.0);
    EXPECT_EQ(fresh.faults(0), (Faults{.reading_frozen = true}));
    // Without power (the short is gone with the old configuration) it cools towards 30 °C.
    next.engine().run_scans(6000);
    EXPECT_LT(fresh.true_temperature(0), hot.true_temperature(0) - 50.0);
}

TEST(Plant, ChangingDeadTimeAtRunTimeKeepsThePowerInFlight) {
    ChannelParams c;
    c.dead_time_s = 5;
    Rig rig(c);
    rig.image.set_word(Area::R, 200, 16383);
    rig.run_seconds(100);
    const double t0 = rig.plant->true_temperature(0);
    ChannelParams p = rig.plant->params(0);
    p.dead_time_s = 60;  // a longer line: the power of the last minute is assumed as it was
    rig.plant->set_params(0, p);
    rig.run_seconds(10);
    EXPECT_GT(rig.plant->true_temperature(0), t0);
    p.tau_s = -5;  // clamped
    rig.plant->set_params(0, p);
    EXPECT_EQ(rig.plant->params(0).tau_s, 0.1);
}

// A channel at rest (no power, none within the dead time, at ambient) is not visited by the
// scans; each way of disturbing it must wake it, or it would stay where it was left.
TEST(Plant, ARestingChannelWakesForEveryChangeThatMovesIt) {
    Rig rig(no_dead_time());  // channel 0 driven by R200; channels 1-31 undriven
    rig.run_seconds(10);      // everything at rest
    ASSERT_EQ(rig.plant->true_temperature(1), 25.0);

    rig.plant->set_temperature(1, 100.0);  // a process set hot cools back
    rig.run_seconds(60);
    EXPECT_LT(rig.plant->true_temperature(1), 95.0);
    EXPECT_GT(rig.plant->true_temperature(1), 25.0);

    rig.plant->set_faults(2, {.heater_shorted = true});  // a shorted heater heats, undriven
    rig.run_seconds(60);
    EXPECT_GT(rig.plant->true_temperature(2), 100.0);

    ChannelParams warm = rig.plant->params(3);
    warm.ambient_c = 40.0;  // a new ambient pulls the process towards it
    rig.plant->set_params(3, warm);
    rig.run_seconds(60);
    EXPECT_GT(rig.plant->true_temperature(3), 30.0);

    PlantState s = rig.plant->state();
    s[4].process_c = 200.0;  // a restored process goes on from where it was
    rig.plant->restore(s);
    rig.run_seconds(60);
    EXPECT_LT(rig.plant->true_temperature(4), 190.0);
}

TEST(Plant, ADriveAddedOrRemovedAtRunTimeTakesEffectAtTheNextScan) {
    Rig rig(no_dead_time());
    rig.image.set_word(Area::R, 201, 16383);
    rig.run_seconds(10);
    EXPECT_EQ(rig.plant->true_temperature(5), 25.0);  // undriven: R201 means nothing to it

    rig.plant->set_drive(5, Drive{Drive::Kind::Register, {Area::R, 201, false}, 16383});
    rig.run_seconds(60);
    EXPECT_GT(rig.plant->true_temperature(5), 100.0);
    EXPECT_NEAR(rig.plant->drive_now(5), 1.0, 1e-9);

    // Removed while at full power: the power it had latched goes to 0 with the next scan.
    rig.plant->set_drive(5, Drive{});
    rig.run_seconds(0.02);
    EXPECT_EQ(rig.plant->drive_now(5), 0.0);
    const double hot = rig.plant->true_temperature(5);
    rig.run_seconds(60);
    EXPECT_LT(rig.plant->true_temperature(5), hot);
}

TEST(History, ExactMeansOfAPiecewiseConstantSignal) {
    History h;
    h.add(0, 10, 1.0);
    h.add(10, 15, 0.0);
    h.add(15, 40, 0.5);
    h.add(40, 50, 0.5);  // same value: the last segment grows, no new point
    EXPECT_EQ(h.size(), 4u);
    EXPECT_DOUBLE_EQ(h.mean(0, 10), 1.0);
    EXPECT_DOUBLE_EQ(h.mean(5, 12), 5.0 / 7.0);
    EXPECT_DOUBLE_EQ(h.mean(0, 50), (10 * 1.0 + 35 * 0.5) / 50.0);
    EXPECT_DOUBLE_EQ(h.mean(-10, 0), 0.0);  // before power-up: off
    h.forget_before(12);                    // [0, 10) goes; [10, 15) is still needed
    EXPECT_EQ(h.size(), 3u);
    EXPECT_DOUBLE_EQ(h.mean(-20, 10), 1.0);  // forgotten: the value the signal had then
    EXPECT_DOUBLE_EQ(h.mean(12, 50), 35 * 0.5 / 38.0);
    h.forget_before(45);
    EXPECT_EQ(h.size(), 2u);
    EXPECT_DOUBLE_EQ(h.mean(45, 50), 0.5);
}

// Issue 3 item 5: the same config, the same Modbus writes at the same simulated times (noise on,
// fixed seed) give the same registers, every one of them, and the same plant.
TEST(Determinism, SameConfigSameWritesSameRegisters) {
    const std::string yaml = R"(
profile: fbs
temperature: {table: R5000, modules: [TC6:K, RTD6:PT100_DIN]}
plant:
  seed: 1234
  defaults: {noise: 0.3}
init:
  R5000: [0xA556, 2, 10000, 20000, 0x0101, 0x0002]
  R100: [1500, 1200, 900]
  R110: [50, 50, 50]
program:
  - MOV: {en: M1926, s: WM800, d: R4012}
  - TPCTL: {en: M0, hc: 1, md: 0, sn: 0, zn: 3, yn: Y30, sv: R100, os: R110, pr: R120,
            ir: R130, dr: R140, or: R200, wr: R300, err: M100, alm: M101}
)";
    auto run = [&](std::vector<std::uint8_t>& storage, std::vector<double>& temps) {
        daemon::Plc plc(config::parse_config(yaml, "det.yaml"));
        testing::Wire wire(plc);
        auto& e = plc.engine();
        e.run_scans(500);
        wire.tcp(1, testing::write_coils_pdu(2800, {true, true, true}));  // M800-M802
        wire.tcp(1, testing::write_single_pdu(0x05, 2000, 0xFF00));       // M0
        e.run_scans(30000);
        wire.tcp(1, testing::write_registers_pdu(101, {1300}));  // a new setpoint
        e.run_scans(30000);
        wire.tcp(1, testing::write_single_pdu(0x05, 2000, 0x0000));
        e.run_scans(1000);
        const auto s = plc.image().storage();
        storage.assign(reinterpret_cast<const std::uint8_t*>(s.data()),
                       reinterpret_cast<const std::uint8_t*>(s.data()) + s.size());
        for (int c = 0; c < kChannels; ++c) temps.push_back(plc.plant().true_temperature(c));
    };
    std::vector<std::uint8_t> a, b;
    std::vector<double> ta, tb;
    run(a, ta);
    run(b, tb);
    ASSERT_EQ(a.size(), b.size());
    std::size_t differing = 0;
    for (std::size_t i = 0; i < a.size(); ++i) differing += a[i] != b[i] ? 1 : 0;
    EXPECT_EQ(differing, 0u);
    EXPECT_EQ(ta, tb);
    // The run did something: the noisy readings of R0-R11 are there.
    std::uint16_t r0 = 0;
    std::memcpy(&r0, a.data() + image::Image::area_offset(testing::fbs_layout(), Area::R), 2);
    EXPECT_GT(r0, 200);  // about 25.0 °C
}

}  // namespace
}  // namespace plcemu::plant
