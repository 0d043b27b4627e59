// Simulator-control unit (docs/simulator-and-plant.md, "Simulator-control unit (unit 247)"; issue 3
// item 4): unit 247's holding registers, through the real dispatcher on the wire, with a fake time
// control.

#include <gtest/gtest.h>

#include "simulator/simulator_unit.hpp"

#include "plcemu/listener/comm_faults.hpp"
#include "support/profiles.hpp"
#include "plcemu/engine/engine.hpp"
#include "plcemu/engine/time_control.hpp"
#include "plcemu/image/image.hpp"
#include "plcemu/modbus/dispatcher.hpp"
#include "support/fake_time.hpp"
#include "support/wire.hpp"

namespace plcemu::simulator {

using plant::ChannelParams;
using plant::Drive;
using plant::Faults;
namespace {

using image::Area;
using testing::exception_of;
using testing::read_pdu;
using testing::reply_words;
using testing::write_registers_pdu;
using testing::write_single_pdu;

constexpr std::uint8_t kSim = 247;

using testing::FakeTime;

// A PLC unit that serves nothing: only unit 247 matters here.
class NoPlc final : public modbus::Unit {
public:
    modbus::Window resolve(modbus::Table, std::uint16_t, std::uint16_t, bool) noexcept override {
        return {};
    }
};

// Unit 247 on its own (kept here: no PLC behind it, only the simulator unit and a fake time).
struct Rig {
    explicit Rig(bool writable = true)
        : image(testing::fbs_layout()),
          faults("", &testing::fbs_naming(), testing::fbs_layout()) {
        engine::EngineOptions o;
        o.scan_period = std::chrono::milliseconds(10);
        engine = std::make_unique<engine::Engine>(image, o, engine::Program{});
        engine->power_up();
        auto p = plant::make_plant(plant::PlantSetup{});
        plant = p.get();
        engine->add_subsystem(std::move(p));
        time = std::make_unique<FakeTime>(*engine);
        unit = std::make_unique<SimulatorUnit>(*plant, *time, writable, &faults,
                                               &testing::fbs_naming());
        dispatcher = std::make_unique<modbus::Dispatcher>(modbus::Identity{});
        wire = std::make_unique<testing::Wire>(*dispatcher, plc, station, unit.get(), kSim);
    }
    std::vector<std::uint16_t> read(std::uint16_t addr, std::uint16_t qty) {
        const auto r = wire->tcp(kSim, read_pdu(0x03, addr, qty));
        EXPECT_EQ(exception_of(r), 0) << "read " << addr;
        return reply_words(r);
    }
    std::uint8_t write(std::uint16_t addr, std::uint16_t v) {
        return exception_of(wire->tcp(kSim, write_single_pdu(0x06, addr, v)));
    }
    std::uint8_t write_many(std::uint16_t addr, const std::vector<std::uint16_t>& v) {
        return exception_of(wire->tcp(kSim, write_registers_pdu(addr, v)));
    }

    image::Image image;
    listener::CommFaults faults;
    std::unique_ptr<engine::Engine> engine;
    plant::Plant* plant = nullptr;
    std::unique_ptr<FakeTime> time;
    std::unique_ptr<SimulatorUnit> unit;
    NoPlc plc;
    std::uint8_t station = 1;
    std::unique_ptr<modbus::Dispatcher> dispatcher;
    std::unique_ptr<testing::Wire> wire;
};

std::uint16_t ch(int c, int offset) { return static_cast<std::uint16_t>(100 + 10 * c + offset); }

TEST(SimulatorUnit, TimeScaleRegister0Is1To10000AndClamped) {
    Rig rig;
    EXPECT_EQ(rig.read(0, 1)[0], 1);
    EXPECT_EQ(rig.write(0, 60), 0);
    EXPECT_EQ(rig.time->scale, 60.0);
    EXPECT_EQ(rig.read(0, 1)[0], 60);
    EXPECT_EQ(rig.write(0, 0), 0);  // below the range: 1
    EXPECT_EQ(rig.time->scale, 1.0);
    EXPECT_EQ(rig.write(0, 20000), 0);  // above: 10000
    EXPECT_EQ(rig.time->scale, 10000.0);
    EXPECT_EQ(rig.read(0, 1)[0], 10000);
}

TEST(SimulatorUnit, FreezeRegister1StopsScans) {
    Rig rig;
    EXPECT_EQ(rig.write(1, 1), 0);
    EXPECT_TRUE(rig.time->frozen());
    EXPECT_EQ(rig.read(1, 1)[0], 1);
    EXPECT_EQ(rig.write(1, 7), 0);  // any non-zero value freezes
    EXPECT_EQ(rig.read(1, 1)[0], 1);
    EXPECT_EQ(rig.write(1, 0), 0);
    EXPECT_FALSE(rig.time->frozen());
    EXPECT_EQ(rig.read(1, 1)[0], 0);
}

TEST(SimulatorUnit, StepRegister2RunsNScans) {
    Rig rig;
    rig.write(1, 1);
    EXPECT_EQ(rig.write(2, 250), 0);
    EXPECT_EQ(rig.time->steps, (std::vector<std::uint64_t>{250}));
    EXPECT_EQ(rig.engine->scans(), 250u);
    EXPECT_EQ(rig.read(2, 1)[0], 0);
    EXPECT_EQ(rig.write(2, 0), 0);  // zero steps: nothing
    EXPECT_EQ(rig.time->steps.size(), 1u);
}

TEST(SimulatorUnit, StepRegister2ReadsTheScansStillQueued) {
    // The daemon runs steps in slices after the reply: a client polls register 2 for 0.
    Rig rig;
    rig.time->queued = 12;
    EXPECT_EQ(rig.read(2, 1)[0], 12);
    rig.time->queued = 1'000'000;  // more than a register holds: reads its largest value
    EXPECT_EQ(rig.read(2, 1)[0], 65535);
    // Writing 0 cancels what is still queued.
    EXPECT_EQ(rig.write(2, 0), 0);
    EXPECT_EQ(rig.time->cancels, 1);
    EXPECT_EQ(rig.read(2, 1)[0], 0);
}

TEST(SimulatorUnit, ReadOnlyUnitRefusesEveryWriteWithException02) {
    Rig rig(false);
    EXPECT_EQ(rig.write(1, 1), 2);
    EXPECT_EQ(rig.write(100, 2), 2);
    EXPECT_FALSE(rig.time->frozen());
    EXPECT_EQ(rig.read(1, 1)[0], 0);
}

TEST(SimulatorUnit, FreezeAndStepInOneWriteFreezeFirst) {
    // Registers are applied in address order: freeze, then step.
    Rig rig;
    EXPECT_EQ(rig.write_many(1, {1, 100}), 0);
    ASSERT_EQ(rig.time->steps.size(), 1u);
    EXPECT_TRUE(rig.time->frozen_when_stepped[0]);
    EXPECT_EQ(rig.engine->scans(), 100u);
}

TEST(SimulatorUnit, SimulatedSecondsAre32BitLowWordFirst) {
    Rig rig;
    rig.time->fixed_time = std::chrono::milliseconds(70000LL * 1000 + 900);  // 70000.9 s
    const auto w = rig.read(3, 2);
    EXPECT_EQ(w[0], 70000 & 0xFFFF);
    EXPECT_EQ(w[1], 70000 >> 16);
    rig.time->fixed_time.reset();
    rig.write(2, 500);                                              // 5 s of scans
    EXPECT_EQ(rig.read(3, 2), (std::vector<std::uint16_t>{4, 0}));  // last scan at 4.99 s
}

TEST(SimulatorUnit, ReadOnlyWordsRefuseWritesWithException02) {
    // Simulated time, true temperature and heater power are read-only; +9 is reserved.
    Rig rig;
    EXPECT_EQ(rig.write(3, 1), 0x02);
    EXPECT_EQ(rig.write(4, 1), 0x02);
    EXPECT_EQ(rig.write(ch(0, 6), 1), 0x02);
    EXPECT_EQ(rig.write(ch(31, 7), 1), 0x02);
    EXPECT_EQ(rig.write(ch(2, 9), 1), 0x02);
    // A multiple write that touches one read-only word changes nothing.
    EXPECT_EQ(rig.write_many(0, {50, 0, 0, 9}), 0x02);
    EXPECT_EQ(rig.time->scale, 1.0);
    EXPECT_EQ(rig.write_many(ch(0, 5), {10, 0}), 0x02);
    EXPECT_EQ(rig.plant->params(0).noise_c, 0.0);
}

TEST(SimulatorUnit, UnmappedAddressesGiveException02AndOnlyHoldingRegistersAreServed) {
    Rig rig;
    EXPECT_EQ(exception_of(rig.wire->tcp(kSim, read_pdu(0x03, 5, 1))), 0x02);
    EXPECT_EQ(exception_of(rig.wire->tcp(kSim, read_pdu(0x03, 99, 2))), 0x02);
    EXPECT_EQ(exception_of(rig.wire->tcp(kSim, read_pdu(0x03, 0, 6))), 0x02);
    EXPECT_EQ(exception_of(rig.wire->tcp(kSim, read_pdu(0x03, 419, 2))), 0x02);
    EXPECT_EQ(exception_of(rig.wire->tcp(kSim, read_pdu(0x03, 420, 1))), 0x02);
    EXPECT_EQ(rig.read(100, 125).size(), 125u);  // blocks with their reserved words
    EXPECT_EQ(rig.read(0, 5).size(), 5u);
    EXPECT_EQ(exception_of(rig.wire->tcp(kSim, read_pdu(0x01, 0, 1))), 0x01);
    EXPECT_EQ(exception_of(rig.wire->tcp(kSim, read_pdu(0x04, 0, 1))), 0x01);
}

TEST(SimulatorUnit, ChannelBlockAt100Plus10cSetsThePlantParameters) {
    // +1 ambient 0.1 °C signed, +2 K 0.1 °C, +3 τ s, +4 θ s, +5 noise 0.01 °C.
    Rig rig;
    EXPECT_EQ(rig.write_many(ch(3, 1), {static_cast<std::uint16_t>(-125), 3000, 60, 7, 25}), 0);
    const ChannelParams& p = rig.plant->params(3);
    EXPECT_EQ(p.ambient_c, -12.5);
    EXPECT_EQ(p.k_c, 300.0);
    EXPECT_EQ(p.tau_s, 60.0);
    EXPECT_EQ(p.dead_time_s, 7.0);
    EXPECT_EQ(p.noise_c, 0.25);
    EXPECT_EQ(rig.read(ch(3, 1), 5),
              (std::vector<std::uint16_t>{static_cast<std::uint16_t>(-125), 3000, 60, 7, 25}));
    // Other channels keep the defaults: 25.0 °C, 400.0 °C, 120 s, 5 s, 0.
    EXPECT_EQ(rig.read(ch(2, 1), 5), (std::vector<std::uint16_t>{250, 4000, 120, 5, 0}));
}

TEST(SimulatorUnit, ChannelParametersAreClampedToTheirRanges) {
    Rig rig;
    rig.write(ch(0, 2), 65535);                              // K at most 3000.0 °C
    rig.write(ch(0, 3), 0);                                  // τ at least 1 s
    rig.write(ch(0, 4), 5000);                               // θ at most 3600 s
    rig.write(ch(0, 5), 60000);                              // noise at most 100.00 °C
    rig.write(ch(0, 1), static_cast<std::uint16_t>(-3000));  // ambient at least -200.0 °C
    EXPECT_EQ(rig.read(ch(0, 1), 5), (std::vector<std::uint16_t>{static_cast<std::uint16_t>(-2000),
                                                                 30000, 1, 3600, 10000}));
}

// docs/simulator-and-plant.md: +8 is an RTD's lead resistance in 0.01 Ω, 0–10000.
TEST(SimulatorUnit, LeadResistanceAt108Plus10c) {
    Rig rig;
    EXPECT_EQ(rig.read(ch(5, 8), 1), std::vector<std::uint16_t>{0});
    EXPECT_EQ(rig.write(ch(5, 8), 150), 0);
    EXPECT_EQ(rig.plant->params(5).lead_ohm, 1.5);
    EXPECT_EQ(rig.plant->sense(5).lead_ohm, 1.5);
    EXPECT_EQ(rig.read(ch(5, 8), 1), std::vector<std::uint16_t>{150});
    EXPECT_EQ(rig.write(ch(5, 8), 65535), 0);  // at most 100.00 Ω
    EXPECT_EQ(rig.read(ch(5, 8), 1), std::vector<std::uint16_t>{10000});
    EXPECT_EQ(rig.write(ch(5, 9), 1), 0x02);  // +9 stays reserved
}

TEST(SimulatorUnit, FaultBitsSensorBrokenHeaterOpenShortedReadingFrozen) {
    Rig rig;
    EXPECT_EQ(rig.write(ch(5, 0), 0b1011), 0);
    const Faults f = rig.plant->faults(5);
    EXPECT_TRUE(f.sensor_broken);
    EXPECT_TRUE(f.heater_open);
    EXPECT_FALSE(f.heater_shorted);
    EXPECT_TRUE(f.reading_frozen);
    EXPECT_EQ(rig.read(ch(5, 0), 1)[0], 0b1011);
    rig.write(ch(5, 0), 0xFFF4);  // undefined bits are ignored
    EXPECT_EQ(rig.read(ch(5, 0), 1)[0], 0b0100);
    EXPECT_TRUE(rig.plant->faults(5).heater_shorted);
    EXPECT_FALSE(rig.plant->faults(4).heater_shorted);
}

TEST(SimulatorUnit, TrueTemperatureAndHeaterPowerAreLive) {
    // +6 true temperature 0.1 °C signed, +7 heater power 0.1 %.
    Rig rig;
    rig.plant->set_temperature(1, 123.46);
    rig.plant->set_temperature(2, -40.0);
    EXPECT_EQ(rig.read(ch(1, 6), 1)[0], 1235);
    EXPECT_EQ(rig.read(ch(2, 6), 1)[0], static_cast<std::uint16_t>(-400));
    EXPECT_EQ(rig.read(ch(0, 7), 1)[0], 0);
    rig.write(ch(0, 0), 0b0100);  // heater shorted: full power
    rig.write(2, 1000);           // 10 s
    EXPECT_EQ(rig.read(ch(0, 7), 1)[0], 1000);
    EXPECT_GT(static_cast<std::int16_t>(rig.read(ch(0, 6), 1)[0]), 250);
}

// Communication faults (docs/communication-faults.md, "On the simulator-control unit"): the
// block at 20-40, written as one.
TEST(SimulatorUnit, CommFaultBlockSwitchesTheFaultsAsOne) {
    Rig rig;
    // delay 100-300, exception 6, scope R100 x10 ("R1" "00").
    std::vector<std::uint16_t> block(19, 0);
    block[0] = 100;
    block[1] = 300;
    block[4] = 9;
    block[5] = 6;
    block[8] = 2;   // disconnect with RST ...
    block[9] = 5;   // ... after 5
    block[10] = 1;  // garble crc
    block[14] = 0x5231;
    block[15] = 0x3030;
    block[18] = 10;
    EXPECT_EQ(rig.write_many(20, block), 0);
    const config::CommFaultSettings& s = rig.faults.settings();
    EXPECT_EQ(s.delay_min_ms, 100u);
    EXPECT_EQ(s.delay_max_ms, 300u);
    EXPECT_EQ(s.seed, 9u);
    EXPECT_EQ(s.exception, 6);
    EXPECT_EQ(s.disconnect_after, 5u);
    EXPECT_TRUE(s.reset);
    EXPECT_EQ(s.garble, config::Garble::Crc);
    EXPECT_EQ(s.devices, (image::Range{Area::R, 100, 10}));
    // It reads back as written, with b0 of the status: a fault is on.
    const auto r = rig.read(20, 21);
    EXPECT_EQ(std::vector<std::uint16_t>(r.begin(), r.begin() + 19), block);
    EXPECT_EQ(r[20], 1);
    // One register alone switches from what the block held.
    EXPECT_EQ(rig.write(25, 0), 0);
    EXPECT_EQ(rig.faults.settings().exception, 0);
    EXPECT_EQ(rig.faults.settings().delay_max_ms, 300u);
    // Clear: everything off, status 0.
    EXPECT_EQ(rig.write(39, 1), 0);
    EXPECT_FALSE(rig.faults.active());
    EXPECT_FALSE(rig.faults.settings().devices);
    EXPECT_EQ(rig.read(39, 2), (std::vector<std::uint16_t>{0, 0}));
}

TEST(SimulatorUnit, CommFaultWriteThatMakesNoSenseIsRefusedAsAWhole) {
    Rig rig;
    EXPECT_EQ(rig.write(26, 1), 0);  // offline
    EXPECT_TRUE(rig.faults.settings().offline);
    // "Q5": no device of the PLC. Nothing changes, status b1 says so.
    EXPECT_EQ(rig.write_many(34, {0x5135, 0, 0, 0}), 0);
    EXPECT_TRUE(rig.faults.settings().offline);
    EXPECT_FALSE(rig.faults.settings().devices);
    EXPECT_EQ(rig.read(40, 1)[0], 3);
    // "R9000": a name, but beyond the PLC's R area (R0-R8071 on an FBs).
    EXPECT_EQ(rig.write_many(34, {0x5239, 0x3030, 0x3000, 0}), 0);
    EXPECT_FALSE(rig.faults.settings().devices);
    EXPECT_EQ(rig.read(40, 1)[0], 3);
    // Both drops at once: refused too.
    EXPECT_EQ(rig.write_many(34, {0, 0, 0, 0}), 0);
    EXPECT_EQ(rig.read(40, 1)[0], 1);
    EXPECT_EQ(rig.write_many(22, {2, 5000}), 0);
    EXPECT_EQ(rig.read(40, 1)[0], 3);
    EXPECT_EQ(rig.faults.settings().drop_every, 0u);
    // Clamped like every register: 70000 ms is out of a word, 65535 clamps to 60000.
    EXPECT_EQ(rig.write_many(20, {65535, 0}), 0);
    EXPECT_EQ(rig.faults.settings().delay_min_ms, 60000u);
    EXPECT_EQ(rig.faults.settings().delay_max_ms, 60000u);
    // The status word is read-only.
    EXPECT_EQ(rig.write(40, 0), 2);
}

}  // namespace
}  // namespace plcemu::simulator
