// The VB temperature modules (VB manual FNC88/FNC92 examples; docs/profile-vb.md, "Temperature
// modules") and the `modules:` section.

#include <gtest/gtest.h>

#include <array>
#include <string>

#include "plcemu/config/config.hpp"
#include "plcemu/image/image.hpp"
#include "plcemu/profiles/profile.hpp"
#include "profiles/vb/modules_config.hpp"
#include "profiles/vb/settings.hpp"
#include "profiles/vb/temperature_modules.hpp"

namespace plcemu::profiles::vb {
namespace {

// A sensor per channel, set by the test.
class Sensors final : public engine::SensorSource {
public:
    engine::SensorSample sense(int channel) noexcept override {
        return samples.at(static_cast<std::size_t>(channel));
    }
    std::array<engine::SensorSample, 32> samples{};
};

std::vector<ModuleConfig> parse(const std::string& modules) {
    return settings_of(config::parse_config("profile: vb\nmodules: " + modules + "\n", "t"))
        ->modules;
}

std::uint16_t word(TemperatureModules& m, int module, int w) {
    std::uint16_t v = 0xDEAD;
    EXPECT_TRUE(m.read(module, w, v)) << "module " << module << " CR#" << w;
    return v;
}

// The VB's temperature modules on their own (kept here: no PLC, one input pass per scan()).
struct Rig {
    explicit Rig(const std::string& modules)
        : m(parse(modules), sensors) {}
    void scan() {
        engine::ScanContext ctx{img, {}, {}, 0, true};
        m.inputs(ctx);
    }
    image::Image img{profiles::find("vb")->layout()};
    Sensors sensors;
    TemperatureModules m;
};

// CR#32… hold the readings in 0.1 °C; plant channels run across modules in bus order.
TEST(VbModules, ReadingsInTenthsAcrossModules) {
    Rig r("[VB-4T, VB-2PT]");
    r.sensors.samples[0] = {false, 25.04};
    r.sensors.samples[3] = {false, -12.35};
    r.sensors.samples[4] = {false, 431.26};
    r.scan();
    EXPECT_EQ(word(r.m, 1, 32), 250);
    EXPECT_EQ(static_cast<std::int16_t>(word(r.m, 1, 35)), -124);
    EXPECT_EQ(word(r.m, 2, 32), 4313);
}

// CR#20 and CR#29 b14 ("ready") from the first scan, even after a TO wrote them.
TEST(VbModules, StatusReadyInBothWords) {
    Rig r("[VB-8T]");
    ASSERT_TRUE(r.m.write(1, 20, 0));
    r.scan();
    EXPECT_EQ(word(r.m, 1, 20), cr::kReady);
    EXPECT_EQ(word(r.m, 1, 29), cr::kReady);
}

// CR#0…: the power-up mode (7 for TC, 1 for Pt100, or `mode:`); 0 disables the channel.
TEST(VbModules, ModesFromConfigAndModeZeroReadsZero) {
    Rig r("[VB-4T, VB-4PT, {type: VB-2PT, mode: 0}]");
    for (int i = 0; i < 10; ++i) r.sensors.samples[static_cast<std::size_t>(i)] = {false, 100.0};
    r.scan();
    EXPECT_EQ(word(r.m, 1, 0), 7);
    EXPECT_EQ(word(r.m, 2, 3), 1);
    EXPECT_EQ(word(r.m, 3, 0), 0);
    EXPECT_EQ(word(r.m, 3, 32), 0);
    ASSERT_TRUE(r.m.write(1, 1, 0));
    r.scan();
    EXPECT_EQ(word(r.m, 1, 32), 1000);
    EXPECT_EQ(word(r.m, 1, 33), 0);
    // Any non-zero code measures: the manual names only 7, the K type at 0.1 °C.
    ASSERT_TRUE(r.m.write(1, 1, 3));
    ASSERT_TRUE(r.m.write(2, 0, 0xFFFF));
    r.scan();
    EXPECT_EQ(word(r.m, 1, 33), 1000);
    EXPECT_EQ(word(r.m, 2, 32), 1000);
}

// Broken, or outside −50.0…+500.0 °C (K type) / −200.0…+600.0 °C (Pt100): 32767.
TEST(VbModules, BrokenOrOutOfRangeReads32767) {
    Rig r("[VB-4T, VB-4PT]");
    r.sensors.samples[0] = {true, 25.0};
    r.sensors.samples[1] = {false, 500.04};
    r.sensors.samples[2] = {false, -50.1};
    r.sensors.samples[3] = {false, 500.0};
    r.sensors.samples[4] = {false, 550.0};
    r.sensors.samples[5] = {false, -200.1};
    r.scan();
    EXPECT_EQ(word(r.m, 1, 32), cr::kBroken);
    EXPECT_EQ(word(r.m, 1, 33), cr::kBroken);
    EXPECT_EQ(word(r.m, 1, 34), cr::kBroken);
    EXPECT_EQ(word(r.m, 1, 35), 5000);
    EXPECT_EQ(word(r.m, 2, 32), 5500);
    EXPECT_EQ(word(r.m, 2, 33), cr::kBroken);
}

// Module 0, a module past the last, and CR#64 on do not exist.
TEST(VbModules, NoSuchWord) {
    Rig r("[VB-2PT]");
    std::uint16_t v = 0;
    EXPECT_FALSE(r.m.read(0, 0, v));
    EXPECT_FALSE(r.m.read(2, 0, v));
    EXPECT_FALSE(r.m.read(1, 64, v));
    EXPECT_FALSE(r.m.read(1, -1, v));
    EXPECT_FALSE(r.m.write(1, 64, 1));
    EXPECT_TRUE(r.m.read(1, 63, v));
}

TEST(VbModulesConfig, ErrorsAtLineAndColumn) {
    auto error = [](const std::string& modules) {
        try {
            parse(modules);
        } catch (const config::ConfigError& e) {
            return std::string(e.what());
        }
        return std::string("no error");
    };
    EXPECT_EQ(error("[VB-8X]"),
              "t:2:11: modules.type: unknown module 'VB-8X' (expected VB-8T, VB-4T, VB-4PT or "
              "VB-2PT)");
    EXPECT_EQ(error("[{mode: 7}]"), "t:2:11: modules entry: 'type' is required");
    EXPECT_EQ(
        error("[VB-8T, VB-8T, VB-8T, VB-8T, VB-8T, VB-8T, VB-8T, VB-8T, VB-2PT]").substr(0, 8),
        "t:2:39: ");  // the fifth VB-8T makes 40 channels
    EXPECT_EQ(error("{a: 1}"),
              "t:2:10: modules: expected a list such as [VB-8T, {type: VB-4PT, mode: 1}]");
}

// A few lines of YAML aliases can stand for an exponential tree: refused, not expanded.
TEST(ConfigTree, AliasBombIsRefused) {
    std::string text = "profile: vb\na0: &a0 [x, x, x, x, x, x, x, x, x, x]\n";
    for (int i = 1; i < 10; ++i) {
        const std::string p = "a" + std::to_string(i - 1);
        text += "a" + std::to_string(i) + ": &a" + std::to_string(i) + " [*" + p + ", *" + p +
                ", *" + p + ", *" + p + ", *" + p + ", *" + p + ", *" + p + ", *" + p + ", *" + p +
                ", *" + p + "]\n";
    }
    try {
        config::parse_config(text, "t");
        FAIL() << "accepted";
    } catch (const config::ConfigError& e) {
        EXPECT_NE(std::string(e.what()).find("repeats too much"), std::string::npos) << e.what();
    }
}

}  // namespace
}  // namespace plcemu::profiles::vb
