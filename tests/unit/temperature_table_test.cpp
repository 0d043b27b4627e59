// FBs temperature measurement (FBs manual §21.3): configuration table, execute codes,
// channel numbering, working registers, R4009/R4010/R4011/R4015, conversion times, ranges.

#include <gtest/gtest.h>

#include <vector>

#include "profiles/fbs/temperature_table.hpp"
#include "profiles/fbs/specials.hpp"
#include "support/profiles.hpp"
#include "plcemu/engine/engine.hpp"
#include "profiles/fbs/special_registers.hpp"
#include "plcemu/image/image.hpp"

namespace plcemu::profiles::fbs {
namespace {

using image::Area;
using std::chrono::milliseconds;
namespace t = temperature;

// Sensors whose temperatures a test sets; counts the samples per channel.
class FakeSensors final : public engine::SensorSource {
public:
    FakeSensors() { celsius.fill(25.0); }
    engine::SensorSample sense(int ch) noexcept override {
        ++samples[static_cast<std::size_t>(ch)];
        return {broken[static_cast<std::size_t>(ch)], celsius[static_cast<std::size_t>(ch)]};
    }
    std::array<double, 32> celsius{};
    std::array<bool, 32> broken{};
    std::array<int, 32> samples{};
};

constexpr std::uint16_t kTC6 = 1, kRTD6 = 2, kTC16 = 3, kRTD16 = 4, kTC2 = 5;
constexpr std::uint16_t kK = 1, kB = 5, kPt100 = 0, kPt1000 = 2;

std::uint16_t module(std::uint16_t name, std::uint16_t sensor) {
    return static_cast<std::uint16_t>(sensor << 8 | name);
}

ModuleConfig installed(std::uint8_t name, std::uint8_t sensor) {
    ModuleConfig m;
    m.name_code = name;
    m.sensor_type = sensor;
    return m;
}

// Table at R5000, readings at R0 (10000), working registers at D0 (20000), 10 ms scans. Kept
// here: the temperature-table subsystem on its own, with sensors this test sets.
struct Rig {
    explicit Rig(std::vector<ModuleConfig> chain = {installed(kTC6, kK), installed(kRTD6, kPt100)},
                 bool fast = false)
        : image(testing::fbs_layout()) {
        engine::EngineOptions o;
        o.scan_period = milliseconds(10);
        engine =
            std::make_unique<engine::Engine>(image, o, engine::Program{}, make_specials(0x0118));
        engine->power_up();
        TemperatureOptions opt;
        opt.table = {Area::R, 5000, false};
        opt.installed = std::move(chain);
        opt.fast = fast;
        opt.main_unit_outputs = 10;
        auto m = std::make_unique<TemperatureTable>(opt, sensors);
        table = m.get();
        engine->add_subsystem(std::move(m));
    }
    void write_table(const std::vector<std::uint16_t>& words) {
        for (std::size_t i = 0; i < words.size(); ++i) {
            image.set_word(Area::R, 5000 + static_cast<std::uint32_t>(i), words[i]);
        }
    }
    void standard_table() {
        write_table({0xA556, 2, 10000, 20000, module(kTC6, kK), module(kRTD6, kPt100)});
    }
    void run_ms(long long ms) { engine->run_scans(static_cast<std::uint64_t>(ms / 10)); }
    std::uint16_t wr(std::uint32_t i) const { return image.word(Area::D, i); }
    std::uint8_t code() const { return static_cast<std::uint8_t>(wr(0) >> 8); }
    std::int16_t reading(std::uint32_t ch) const {
        return static_cast<std::int16_t>(image.word(Area::R, ch));
    }

    FakeSensors sensors;
    image::Image image;
    std::unique_ptr<engine::Engine> engine;
    TemperatureTable* table = nullptr;
};

TEST(TemperatureCodes, ModuleNameCodesInTheManualsOrder) {
    // docs/profile-fbs.md, Temperature measurement (in the order of FBs manual §21.3's list):
    // 1 TC6, 2 RTD6, 3 TC16, 4 RTD16, 5 TC2.
    EXPECT_EQ(t::channels_of(kTC6), 6);
    EXPECT_EQ(t::channels_of(kRTD6), 6);
    EXPECT_EQ(t::channels_of(kTC16), 16);
    EXPECT_EQ(t::channels_of(kRTD16), 16);
    EXPECT_EQ(t::channels_of(kTC2), 2);
    EXPECT_EQ(t::channels_of(0), 0);
    EXPECT_EQ(t::channels_of(6), 0);
    EXPECT_TRUE(t::is_rtd(kRTD6));
    EXPECT_FALSE(t::is_rtd(kTC16));
}

TEST(TemperatureCodes, ConversionTimesNormal) {
    // FBs manual §21.1: normal TC2 2 s, TC6 4 s, TC16 6 s, RTD6 2 s, RTD16 4 s.
    EXPECT_EQ(t::conversion_ms(kTC2), 2000);
    EXPECT_EQ(t::conversion_ms(kTC6), 4000);
    EXPECT_EQ(t::conversion_ms(kTC16), 6000);
    EXPECT_EQ(t::conversion_ms(kRTD6), 2000);
    EXPECT_EQ(t::conversion_ms(kRTD16), 4000);
}

TEST(TemperatureCodes, SensorTypeRangesOfManual21_1) {
    // docs/profile-fbs.md, Temperature measurement: TC 0 J, 1 K, 2 T, 3 E, 4 N, 5 B, 6 R, 7 S;
    // RTD 0 Pt100 DIN, 1 Pt100 JIS, 2 Pt1000 DIN, 3 Pt1000 JIS; ranges of FBs manual §21.1.
    struct Case {
        std::uint8_t module, sensor;
        double lo, hi;
    };
    const Case cases[] = {{kTC6, 0, -200, 900},  {kTC6, 1, -190, 1300},  {kTC6, 2, -190, 380},
                          {kTC6, 3, -190, 1000}, {kTC6, 4, -200, 1000},  {kTC6, 5, 350, 1800},
                          {kTC6, 6, 0, 1800},    {kTC6, 7, 0, 1700},     {kRTD6, 0, -200, 850},
                          {kRTD6, 1, -200, 850}, {kRTD16, 2, -200, 600}, {kRTD16, 3, -200, 600}};
    for (const auto& c : cases) {
        double lo = 0, hi = 0;
        ASSERT_TRUE(t::sensor_range(c.module, c.sensor, lo, hi)) << int(c.sensor);
        EXPECT_EQ(lo, c.lo);
        EXPECT_EQ(hi, c.hi);
    }
    double lo = 0, hi = 0;
    EXPECT_FALSE(t::sensor_range(kTC6, 8, lo, hi));
    EXPECT_FALSE(t::sensor_range(kRTD6, 4, lo, hi));
    EXPECT_FALSE(t::sensor_range(9, 0, lo, hi));
}

TEST(TemperatureCodes, RegisterReferencesUseTheR4004Encoding) {
    // docs/profile-fbs.md, Temperature measurement: 10000+n = Rn, 20000+n = Dn, anything else
    // invalid.
    EXPECT_EQ(t::decode_register(10000), (image::Device{Area::R, 0, false}));
    EXPECT_EQ(t::decode_register(15000), (image::Device{Area::R, 5000, false}));
    EXPECT_EQ(t::decode_register(20123), (image::Device{Area::D, 123, false}));
    EXPECT_FALSE(t::decode_register(9999));
    EXPECT_FALSE(t::decode_register(5000));
    EXPECT_FALSE(t::decode_register(30000));
    EXPECT_EQ(t::encode_register({Area::D, 7, false}), 20007);
    EXPECT_EQ(t::encode_register({Area::R, 7, false}), 10007);
}

TEST(TemperatureTable, ValidMarkerA556hRunsMeasurementAndCode56hOnceEveryChannelIsRead) {
    // FBs manual §21.3.2: 56h once every channel was read; TC6 converts its six channels in 4 s.
    Rig rig;
    rig.standard_table();
    rig.sensors.celsius[0] = 150.0;
    rig.run_ms(3990);
    EXPECT_EQ(rig.code(), t::kIdle);
    EXPECT_EQ(rig.reading(0), 1500);  // channel 0 was read after 4/6 s
    rig.run_ms(20);
    EXPECT_EQ(rig.code(), t::kRunning);
    EXPECT_EQ(rig.wr(0) & 0xFF, 0);  // no mismatch
    for (int ch = 1; ch < 12; ++ch) EXPECT_EQ(rig.reading(static_cast<std::uint32_t>(ch)), 250);
}

TEST(TemperatureTable, BadMarkerMeansNoMeasurementAndExecuteCode00h) {
    // FBs manual §21.3.1: SR+0 other than A556h = no temperature measurement.
    Rig rig;
    rig.standard_table();
    rig.run_ms(5000);
    ASSERT_EQ(rig.code(), t::kRunning);
    rig.image.set_word(Area::R, 5000, 0xA555);
    rig.sensors.celsius[0] = 300.0;
    const int before = rig.sensors.samples[0];
    rig.run_ms(5000);
    EXPECT_EQ(rig.code(), t::kIdle);
    EXPECT_EQ(rig.wr(0), 0);
    EXPECT_EQ(rig.reading(0), 250);  // not refreshed
    EXPECT_EQ(rig.sensors.samples[0], before);
}

TEST(TemperatureTable, ModuleCountZeroOrAboveEightGivesFEh) {
    // FBs manual §21.3.2: FEh when the low byte of WR+3 (module count) is 0 or > 8.
    for (std::uint16_t n : {std::uint16_t{0}, std::uint16_t{9}, std::uint16_t{12}}) {
        Rig rig;
        rig.write_table({0xA556, n, 10000, 20000, module(kTC6, kK), module(kRTD6, kPt100)});
        rig.run_ms(7000);
        EXPECT_EQ(rig.code(), t::kBadModuleCount) << n;
        EXPECT_EQ(rig.wr(3), n) << n;
        EXPECT_EQ(rig.sensors.samples[0], 0);
    }
}

TEST(TemperatureTable, MoreThan32ChannelsGivesFFh) {
    // FBs manual §21.3.2: channels numbered across modules; more than 32 → FFh, no measurement.
    Rig rig(std::vector<ModuleConfig>{});
    rig.write_table(
        {0xA556, 3, 10000, 20000, module(kTC16, kK), module(kRTD16, kPt100), module(kTC2, kK)});
    rig.run_ms(7000);
    EXPECT_EQ(rig.code(), t::kTooManyChannels);
    EXPECT_EQ(rig.wr(3), (34 << 8) | 3);
    EXPECT_EQ(rig.sensors.samples[0], 0);
    // Exactly 32 is fine.
    rig.write_table({0xA556, 2, 10000, 20000, module(kTC16, kK), module(kRTD16, kPt100)});
    rig.run_ms(7000);
    EXPECT_EQ(rig.code(), t::kRunning);
    EXPECT_EQ(rig.wr(3), (32 << 8) | 2);
}

TEST(TemperatureTable, InvalidRegisterReferenceMakesTheTableInvalid) {
    // docs/profile-fbs.md, Temperature measurement: SR+2/SR+3 other than 10000+n / 20000+n make the
    // table invalid.
    Rig rig;
    rig.write_table({0xA556, 2, 5, 20000, module(kTC6, kK), module(kRTD6, kPt100)});
    rig.run_ms(5000);
    EXPECT_EQ(rig.code(), t::kIdle);
    EXPECT_EQ(rig.sensors.samples[0], 0);
    // A working-register reference that is not a register: nothing is written anywhere.
    Rig rig2;
    rig2.image.set_word(Area::D, 0, 0x1234);
    rig2.write_table({0xA556, 2, 10000, 7, module(kTC6, kK), module(kRTD6, kPt100)});
    rig2.run_ms(5000);
    EXPECT_EQ(rig2.wr(0), 0x1234);
}

TEST(TemperatureTable, TableAndRegistersMayBeDRegisters) {
    // Manual 21.3: "Rxxxx or Dxxxx" for readings and working registers.
    Rig rig({installed(kTC2, kK)});
    rig.write_table({0xA556, 1, 20100, 10300, module(kTC2, kK)});
    rig.sensors.celsius[1] = -12.3;
    rig.run_ms(2010);
    EXPECT_EQ(rig.image.word(Area::R, 300) >> 8, t::kRunning);
    EXPECT_EQ(static_cast<std::int16_t>(rig.image.word(Area::D, 101)), -123);
}

TEST(TemperatureTable, InstalledModuleMismatchSetsBitKMinus1OfWr0LowByte) {
    // FBs manual §21.3.2: a table module k that differs from the installed one sets bit k−1 of
    // WR+0's low byte. Decision: its channels read as broken (32767 and the abnormal bit).
    Rig rig({installed(kTC6, kK), installed(kRTD6, kPt100)});
    rig.write_table(
        {0xA556, 3, 10000, 20000, module(kTC6, kK), module(kTC16, kK), module(kTC2, kK)});
    rig.run_ms(6010);
    EXPECT_EQ(rig.wr(0), (t::kRunning << 8) | 0b110);
    EXPECT_EQ(rig.reading(0), 250);
    for (std::uint32_t ch = 6; ch < 24; ++ch) EXPECT_EQ(rig.reading(ch), t::kBroken) << ch;
    EXPECT_EQ(rig.wr(1), 0xFFC0);  // channels 6-15
    EXPECT_EQ(rig.wr(2), 0x00FF);  // channels 16-23
    EXPECT_EQ(rig.sensors.samples[6], 0);
}

TEST(TemperatureTable, NoDeclaredChainMeansTheTableIsWhatIsInstalled) {
    Rig rig(std::vector<ModuleConfig>{});
    rig.standard_table();
    rig.run_ms(4010);
    EXPECT_EQ(rig.wr(0), t::kRunning << 8);
}

TEST(TemperatureTable, ChannelsAreNumberedAcrossModulesInTableOrder) {
    // FBs manual §21.3: module 1's channels first, then module 2's; one reading register each.
    Rig rig;
    for (int ch = 0; ch < 12; ++ch) rig.sensors.celsius[static_cast<std::size_t>(ch)] = 100.0 + ch;
    rig.standard_table();
    rig.run_ms(4010);
    for (std::uint32_t ch = 0; ch < 12; ++ch) {
        EXPECT_EQ(rig.reading(ch), 1000 + 10 * static_cast<int>(ch)) << ch;
    }
    EXPECT_EQ(rig.reading(12), 0);
}

TEST(TemperatureTable, WorkingRegisterLayout4NPlus4) {
    // FBs manual §21.3.2: WR+3 total channels | module count; per module k: [sensor | first Y of
    // its 8 outputs], [channel count | input register index], reading start (encoded), current
    // channel. Decision: the modules follow the main unit (FBs-24MC: Y0-Y9) on the chain.
    Rig rig;
    rig.image.set_word(Area::D, 12, 0x5555);  // just past the 4·2 + 4 words
    rig.standard_table();
    rig.run_ms(4010);
    EXPECT_EQ(rig.wr(3), (12 << 8) | 2);
    EXPECT_EQ(rig.wr(4), (kK << 8) | 10);
    EXPECT_EQ(rig.wr(5), (6 << 8) | 0);
    EXPECT_EQ(rig.wr(6), 10000);
    EXPECT_EQ(rig.wr(8), (kPt100 << 8) | 18);
    EXPECT_EQ(rig.wr(9), (6 << 8) | 1);
    EXPECT_EQ(rig.wr(10), 10006);
    EXPECT_EQ(rig.wr(12), 0x5555);
    // Current channel: the module-local channel being converted, one after another.
    const std::uint16_t c0 = rig.wr(7);
    rig.run_ms(670);  // one TC6 slot (4 s / 6)
    EXPECT_EQ(rig.wr(7), (c0 + 1) % 6);
    EXPECT_LT(rig.wr(11), 6);
}

TEST(TemperatureTable, ChannelsRefreshOneAfterAnotherWithinTheConversionTime) {
    // docs/profile-fbs.md, Temperature measurement: each module refreshes its channels one after
    // another, a round per conversion time (TC6 normal 4 s: one channel every 667 ms).
    Rig rig;
    rig.standard_table();
    rig.run_ms(680);
    EXPECT_EQ(rig.sensors.samples[0], 1);
    EXPECT_EQ(rig.sensors.samples[1], 0);
    rig.run_ms(670);
    EXPECT_EQ(rig.sensors.samples[1], 1);
    EXPECT_EQ(rig.sensors.samples[2], 0);
    rig.run_ms(40000 - 1350);
    EXPECT_EQ(rig.sensors.samples[0], 10);  // 40 s / 4 s
    EXPECT_EQ(rig.sensors.samples[6], 20);  // RTD6: 2 s
}

TEST(TemperatureTable, FastScanRateHalvesTheTimeWithOneDegreeResolution) {
    // FBs manual §21.3 (scan rate): fast = half the conversion time, resolution 1° (still in 0.1°
    // units).
    Rig rig({installed(kTC6, kK), installed(kRTD6, kPt100)}, true);
    rig.sensors.celsius[0] = 123.46;
    rig.sensors.celsius[7] = -4.6;
    rig.standard_table();
    rig.run_ms(1990);
    EXPECT_EQ(rig.code(), t::kIdle);
    rig.run_ms(20);
    EXPECT_EQ(rig.code(), t::kRunning);
    EXPECT_EQ(rig.reading(0), 1230);
    EXPECT_EQ(rig.reading(7), -50);
    EXPECT_EQ(rig.sensors.samples[0], 1);
    rig.run_ms(38000);
    EXPECT_EQ(rig.sensors.samples[0], 20);  // 40 s / 2 s
}

TEST(TemperatureTable, NormalResolutionIsTenthsSigned) {
    Rig rig;
    rig.sensors.celsius[0] = 123.46;
    rig.sensors.celsius[1] = -4.64;
    rig.standard_table();
    rig.run_ms(4010);
    EXPECT_EQ(rig.reading(0), 1235);
    EXPECT_EQ(rig.reading(1), -46);
}

TEST(TemperatureTable, R4009SelectsCelsiusOrFahrenheit) {
    // R4009 0 °C, 1 °F (FBs manual §21.3).
    Rig rig;
    rig.sensors.celsius[0] = 100.0;
    rig.standard_table();
    rig.run_ms(4010);
    EXPECT_EQ(rig.reading(0), 1000);
    rig.image.set_word(Area::R, profiles::fbs::special::kTempUnit, 1);
    rig.run_ms(4000);
    EXPECT_EQ(rig.reading(0), 2120);
    rig.sensors.celsius[0] = -40.0;
    rig.run_ms(4000);
    EXPECT_EQ(rig.reading(0), -400);
}

TEST(TemperatureTable, R4009LowByteDecidesTheUnit) {
    // FB manual (FUN73 special registers): "low byte = 0 °C, low byte = 1 °F"; the high byte
    // does not count, so 0101h is °F and 0100h °C.
    Rig rig;
    rig.sensors.celsius[0] = 100.0;
    rig.standard_table();
    rig.image.set_word(Area::R, profiles::fbs::special::kTempUnit, 0x0101);
    rig.run_ms(4010);
    EXPECT_EQ(rig.reading(0), 2120);
    rig.image.set_word(Area::R, profiles::fbs::special::kTempUnit, 0x0100);
    rig.run_ms(4000);
    EXPECT_EQ(rig.reading(0), 1000);
    rig.image.set_word(Area::R, profiles::fbs::special::kTempUnit, 0x0002);  // neither: °C
    rig.run_ms(4000);
    EXPECT_EQ(rig.reading(0), 1000);
}

TEST(TemperatureTable, R4015FourAveragesSixteenReadings) {
    // FB manual (FUN73 special registers): R4015 = 4 is a 16-reading average; above 4 counts
    // as 4 (docs/profile-fbs.md decision).
    Rig rig;
    rig.standard_table();
    rig.image.set_word(Area::R, profiles::fbs::special::kTempAverage, 4);
    for (int i = 1; i <= 20; ++i) {
        rig.sensors.celsius[0] = 10.0 * i;
        rig.run_ms(4000);  // one conversion of channel 0 per round
    }
    EXPECT_EQ(rig.reading(0), 1250);  // mean of 50..200: 125.0
    rig.image.set_word(Area::R, profiles::fbs::special::kTempAverage, 9);
    rig.sensors.celsius[0] = 210.0;
    rig.run_ms(4000);
    EXPECT_EQ(rig.reading(0), 1350);  // mean of 60..210
    rig.image.set_word(Area::R, profiles::fbs::special::kTempAverage, 3);
    rig.sensors.celsius[0] = 220.0;
    rig.run_ms(4000);
    EXPECT_EQ(rig.reading(0), 1850);  // mean of 150..220
}

TEST(TemperatureTable, R4015MovingAverageOfTwoFourEightReadings) {
    // FBs manual §21.3 (times of average), R4015 as in FB manual FUN73: 0 none, 1 two, 2 four,
    // 3 eight readings, moving average.
    Rig rig;
    rig.standard_table();
    rig.image.set_word(Area::R, profiles::fbs::special::kTempAverage, 2);
    const double values[] = {100, 200, 300, 400, 500, 600};
    for (double v : values) {
        rig.sensors.celsius[0] = v;
        rig.run_ms(4000);  // one conversion of channel 0 per round
    }
    EXPECT_EQ(rig.reading(0), 4500);  // mean of 300..600
    rig.image.set_word(Area::R, profiles::fbs::special::kTempAverage, 1);
    rig.sensors.celsius[0] = 700;
    rig.run_ms(4000);
    EXPECT_EQ(rig.reading(0), 6500);  // mean of 600, 700
    rig.image.set_word(Area::R, profiles::fbs::special::kTempAverage, 3);
    rig.sensors.celsius[0] = 800;
    rig.run_ms(4000);
    EXPECT_EQ(rig.reading(0), 4500);  // mean of 100..800
    rig.image.set_word(Area::R, profiles::fbs::special::kTempAverage, 0);
    rig.sensors.celsius[0] = 900;
    rig.run_ms(4000);
    EXPECT_EQ(rig.reading(0), 9000);
}

TEST(TemperatureTable, BrokenSensorReads32767AndSetsWr1Wr2Bit) {
    // docs/profile-fbs.md, Temperature measurement: a broken sensor reads 32767 and sets its bit in
    // WR+1 (0-15) / WR+2.
    Rig rig({installed(kTC16, kK), installed(kTC6, kK)});
    rig.write_table({0xA556, 2, 10000, 20000, module(kTC16, kK), module(kTC6, kK)});
    rig.sensors.broken[3] = true;
    rig.sensors.broken[17] = true;
    rig.run_ms(6010);
    EXPECT_EQ(rig.code(), t::kRunning);
    EXPECT_EQ(rig.reading(3), t::kBroken);
    EXPECT_EQ(rig.reading(17), t::kBroken);
    EXPECT_EQ(rig.wr(1), 1u << 3);
    EXPECT_EQ(rig.wr(2), 1u << 1);
    // Repaired: the bit clears at the next conversion of the channel.
    rig.sensors.broken[3] = false;
    rig.run_ms(6000);
    EXPECT_EQ(rig.reading(3), 250);
    EXPECT_EQ(rig.wr(1), 0);
}

TEST(TemperatureTable, ReadingBeyondTheSensorRangeIsClampedNotBroken) {
    // FBs manual §21.1 gives ranges, not a broken-line rule: beyond its range a channel reads
    // the range's limit with no abnormal bit; only an open sensor reads 32767
    // (docs/profile-fbs.md).
    Rig rig;
    rig.write_table({0xA556, 2, 10000, 20000, module(kTC6, kK), module(kRTD6, kPt1000)});
    rig.sensors.celsius[0] = 1300.0;  // K: top of the range
    rig.sensors.celsius[1] = 1300.5;  // above: reads 1300.0
    rig.sensors.celsius[2] = -190.5;  // below: reads -190.0
    rig.sensors.celsius[6] = 600.0;   // Pt1000: top of the range
    rig.sensors.celsius[7] = 650.0;   // Pt1000: above 600, reads 600.0
    rig.sensors.broken[3] = true;     // open: broken
    rig.run_ms(4010);
    EXPECT_EQ(rig.reading(0), 13000);
    EXPECT_EQ(rig.reading(1), 13000);
    EXPECT_EQ(rig.reading(2), -1900);
    EXPECT_EQ(rig.reading(3), t::kBroken);
    EXPECT_EQ(rig.reading(6), 6000);
    EXPECT_EQ(rig.reading(7), 6000);
    EXPECT_EQ(rig.wr(1), 1u << 3);
    // Type B starts at 350 °C: a B thermocouple at room temperature reads 350.0 °C, not broken.
    rig.write_table({0xA556, 1, 10000, 20000, module(kTC6, kB)});
    rig.run_ms(4010);
    EXPECT_EQ(rig.reading(4), 3500);
    EXPECT_EQ(rig.wr(1), 1u << 3);  // only the open one
    // In °F the limit converts too: 350 °C is 662 °F.
    rig.image.set_word(Area::R, profiles::fbs::special::kTempUnit, 1);
    rig.run_ms(4000);
    EXPECT_EQ(rig.reading(4), 6620);
}

TEST(TemperatureTable, R4010R4011BitZeroReadsZeroWithoutBrokenCheck) {
    // FBs manual §21.3.3: a channel whose R4010/R4011 bit is 0 reads 0 and is not checked for a
    // broken line.
    Rig rig({installed(kTC16, kK), installed(kTC6, kK)});
    rig.write_table({0xA556, 2, 10000, 20000, module(kTC16, kK), module(kTC6, kK)});
    rig.sensors.broken[2] = true;
    rig.sensors.broken[18] = true;
    rig.sensors.celsius[5] = 80.0;
    rig.image.set_word(Area::R, profiles::fbs::special::kSensorInstalled,
                       0xFFFF & ~(1u << 2 | 1u << 5));
    rig.image.set_word(Area::R, profiles::fbs::special::kSensorInstalled + 1, 0xFFFF & ~(1u << 2));
    rig.run_ms(6010);
    EXPECT_EQ(rig.code(), t::kRunning);
    EXPECT_EQ(rig.reading(2), 0);
    EXPECT_EQ(rig.reading(5), 0);
    EXPECT_EQ(rig.reading(18), 0);
    EXPECT_EQ(rig.wr(1), 0);
    EXPECT_EQ(rig.wr(2), 0);
    EXPECT_EQ(rig.sensors.samples[5], 0);
}

TEST(TemperatureTable, ChangedTableIsReReadAndMeasurementRestarts) {
    // docs/profile-fbs.md, Temperature measurement: a changed table is re-read at the next scan;
    // execute code 00h until every channel was read again.
    Rig rig;
    rig.standard_table();
    rig.run_ms(4010);
    ASSERT_EQ(rig.code(), t::kRunning);
    rig.image.set_word(Area::R, 5005, module(kRTD6, 1));  // module 2 sensor: Pt100 JIS
    rig.run_ms(10);
    EXPECT_EQ(rig.code(), t::kIdle);
    rig.run_ms(3980);
    EXPECT_EQ(rig.code(), t::kIdle);
    rig.run_ms(20);
    EXPECT_EQ(rig.code(), t::kRunning);
    EXPECT_EQ(rig.wr(8) >> 8, 1);
    // A word past the table (SR+4+N) is not part of it: no restart.
    rig.image.set_word(Area::R, 5006, 0x7777);
    rig.run_ms(10);
    EXPECT_EQ(rig.code(), t::kRunning);
}

// A power-up restarts the measurement: the table is read anew and execute code 00h holds until
// every channel was read again.
TEST(TemperatureTable, APowerUpRestartsTheMeasurement) {
    Rig rig;
    rig.standard_table();
    rig.run_ms(4010);
    ASSERT_EQ(rig.code(), t::kRunning);
    rig.engine->power_up();
    rig.run_ms(10);
    EXPECT_EQ(rig.code(), t::kIdle);
    rig.run_ms(3980);
    EXPECT_EQ(rig.code(), t::kIdle);
    rig.run_ms(20);
    EXPECT_EQ(rig.code(), t::kRunning);
}

TEST(TemperatureTable, InvalidSensorCodeReadsBroken) {
    // Decision: a sensor code that is not one of the module's types reads as a broken sensor.
    Rig rig;
    rig.write_table({0xA556, 2, 10000, 20000, module(kTC6, kK), module(kRTD6, 7)});
    rig.run_ms(4010);
    EXPECT_EQ(rig.code(), t::kRunning);
    EXPECT_EQ(rig.reading(0), 250);
    EXPECT_EQ(rig.reading(6), t::kBroken);
    EXPECT_EQ(rig.wr(1), 0x0FC0);
}

}  // namespace
}  // namespace plcemu::profiles::fbs
