// The FATEK FB profile (docs/profile-fb.md): identity and model grammar, the FATEK device
// spelling, the device areas with D0–D3071 and their retentive defaults, the special registers
// R4004–R4023 at every start, the Modbus map (FATEK's table without the R3968 remap: R3968–R3999
// plain registers, FC02/FC04 exception 01, D2999 unmapped), and `temperature.modules`.

#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "plcemu/config/config.hpp"
#include "plcemu/daemon/plc.hpp"
#include "plcemu/modbus/address_map.hpp"
#include "profiles/fb/temperature_config.hpp"
#include "support/config_errors.hpp"
#include "support/plc_rig.hpp"
#include "support/profiles.hpp"
#include "support/wire.hpp"

namespace plcemu::profiles {
namespace {

using image::Area;
using image::Device;
using image::Range;

const Profile& fb() { return testing::profile("fb"); }

// An FB PLC built from config text (the profile line is added).
struct Rig : testing::WiredPlcRig {
    explicit Rig(const std::string& yaml = "")
        : WiredPlcRig("profile: fb\n" + yaml, "fb.yaml") {}
    std::uint8_t fc_exception(std::uint8_t fc, std::uint16_t addr) {
        return testing::exception_of(wire.tcp(1, testing::read_pdu(fc, addr, 1)));
    }
};

// ---- identity

TEST(FbProfile, Identity) {
    EXPECT_EQ(fb().name(), "fb");
    EXPECT_EQ(fb().title(), "FATEK FB");
    EXPECT_EQ(fb().vendor(), "FATEK");
    EXPECT_EQ(fb().default_model(), "FB-40MC");
    EXPECT_EQ(fb().max_station(), 254);
    EXPECT_EQ(fb().sections(), (std::vector<std::string_view>{"temperature"}));
    // A state-file number of its own.
    for (const Profile* p : all()) {
        if (p != &fb()) {
            EXPECT_NE(p->family(), fb().family()) << p->name();
        }
    }
}

// docs/profile-fb.md, "Identity": FB-<points><MA|MC>; R4167 low byte points, high byte 0 MA /
// 1 MC (so FB-40MC → 0128h).
TEST(FbProfile, ModelGrammarAndCode) {
    for (const char* ok : {"FB-40MC", "FB-14MA", "FB-20MC", "FB-28MA", "FB-60MC"}) {
        EXPECT_TRUE(fb().valid_model(ok)) << ok;
    }
    for (const char* bad :
         {"", "FB-", "FB-40", "FB-40MN", "FB-44MC", "FBs-24MC", "FB-40mc", "FB40MC", "FB-040MC"}) {
        EXPECT_FALSE(fb().valid_model(bad)) << bad;
    }
    Rig rig;
    rig.scan();
    EXPECT_EQ(rig.r(4167), 0x0128);
    Rig ma("model: FB-20MA\n");
    ma.scan();
    EXPECT_EQ(ma.r(4167), 0x0014);
}

// ---- devices

TEST(FbLayout, AreasAsFbsButDEndsAtD3071) {
    const image::Layout l = fb().layout();
    EXPECT_TRUE(l.contains(Range{Area::D, 0, 3072}));
    EXPECT_FALSE(l.contains(Range{Area::D, 3072, 1}));
    // R0-R4167 and R5000-R8071: R4168-R4999 exist on no FATEK PLC (a hole in the image).
    EXPECT_TRUE(l.contains(Range{Area::R, 0, 4168}));
    EXPECT_FALSE(l.contains(Range{Area::R, 4168, 1}));
    EXPECT_FALSE(l.contains(Range{Area::R, 4999, 1}));
    EXPECT_TRUE(l.contains(Range{Area::R, 5000, 3072}));
    EXPECT_FALSE(l.contains(Range{Area::R, 5000, 3073}));
    EXPECT_TRUE(l.contains(Range{Area::M, 0, 2002}));
    EXPECT_FALSE(l.contains(Range{Area::M, 2002, 1}));
    EXPECT_EQ(fb().naming().parse_device("TMR5"), (Device{Area::TV, 5, false}));
    EXPECT_EQ(fb().naming().parse_device("WM800"), (Device{Area::M, 800, true}));
    EXPECT_EQ(fb().naming().format_range({Area::D, 0, 3072}), "D0-D3071");
}

TEST(FbLayout, RetentiveDefaultsCoverAllOfD) {
    const image::Layout l = fb().layout();
    bool d_all = false, m800 = false;
    for (const Range& r : l.retentive) {
        d_all = d_all || (r.area == Area::D && r.start == 0 && r.count == 3072);
        m800 = m800 || (r.area == Area::M && r.start == 800);
    }
    EXPECT_TRUE(d_all);
    EXPECT_TRUE(m800);  // FB manual FUN73 example: "M800 onward keeps its value"
}

// ---- special registers

// docs/profile-fb.md, "Special registers": R4004–R4023 after start.
TEST(FbSpecials, TemperatureRegistersAtStart) {
    Rig rig;
    rig.scan();
    const std::vector<std::uint16_t> want{333,    0,      90,     600,  350,  0,   0xFFFF,
                                          0xFFFF, 0xFFFF, 0xFFFF, 500,  0,    248, 286,
                                          240,    280,    0x0001, 8000, 1024, 1024};
    std::vector<std::uint16_t> got;
    for (std::uint32_t i = 4004; i < 4024; ++i) got.push_back(rig.r(i));
    EXPECT_EQ(got, want);
    EXPECT_EQ(rig.r(3968), 0);
}

TEST(FbSpecials, FreeAfterStartAndInitWins) {
    Rig rig("init: {R4014: 250}\n");
    rig.scan();
    EXPECT_EQ(rig.r(4014), 250);
    rig.plc.image().set_word(Area::R, 4016, 258);
    rig.scan(5);
    EXPECT_EQ(rig.r(4016), 258);
}

// ---- Modbus map (docs/profile-fb.md, "Modbus map")

TEST(FbMap, NoUserRemap) {
    Rig rig("init: {R0: 1234, R3969: 0, R3970: 0, R3971: 10, R3974: 5, R3977: 5}\n");
    rig.scan();
    EXPECT_EQ(testing::exception_of(rig.wire.tcp(1, testing::write_single_pdu(6, 3968, 0xA55A))),
              0);
    EXPECT_EQ(rig.r(3968), 0xA55A);
    EXPECT_EQ(testing::reply_words(rig.wire.tcp(1, testing::read_pdu(3, 0, 1))),
              std::vector<std::uint16_t>{1234});
    // FC02/FC04 are never served, whatever R3972–R3977 hold.
    EXPECT_EQ(rig.fc_exception(2, 0), 0x01);
    EXPECT_EQ(rig.fc_exception(4, 0), 0x01);
    EXPECT_EQ(rig.fc_exception(4, 3968), 0x01);
}

TEST(FbMap, RowsAndLimits) {
    Rig rig;
    rig.scan();
    EXPECT_EQ(rig.fc_exception(3, 8998), 0);     // D2998
    EXPECT_EQ(rig.fc_exception(3, 8999), 0x02);  // D2999: exists, not mapped
    EXPECT_EQ(rig.fc_exception(3, 5999), 0x02);  // R5999
    EXPECT_EQ(rig.fc_exception(3, 4168), 0x02);  // R4168
    EXPECT_EQ(testing::exception_of(rig.wire.tcp(1, testing::write_single_pdu(6, 3842, 1))),
              0x02);  // IR
    // One request across R3967, the raw readings and R4000 is one range.
    EXPECT_EQ(testing::reply_words(rig.wire.tcp(1, testing::read_pdu(3, 3967, 34))).size(), 34u);
    int raw_rows = 0;
    for (const modbus::MapRow& row : fb().map().rows()) {
        if (row.devices.area == Area::R && row.devices.start == 3968) {
            ++raw_rows;
            EXPECT_EQ(row.count, 32);
            EXPECT_NE(row.label.find("no user remap"), std::string::npos);
        }
    }
    EXPECT_EQ(raw_rows, 1);
    EXPECT_TRUE(fb().map().dynamic_notes().empty());
    EXPECT_EQ(rig.fc_exception(2, 9999), 0x01);
}

// ---- temperature.modules (docs/profile-fb.md, "Temperature modules")

TEST(FbTemperatureModules, Refusals) {
    struct Case {
        const char* text;
        int line, col;
        const char* needle;
    };
    const Case cases[] = {
        {"temperature:\n  table: R100\n", 3, 10, "temperature.table is not valid in profile fb"},
        {"temperature:\n  modules: [FB-2AK4, FB-4AK24]\n", 3, 22,
         "FB-4AK24 cannot be used together with the FB-2AK4 at fb.yaml:3:13"},
        {"temperature:\n  modules: [FB-4AJ16, FB-2AH4]\n", 3, 23,
         "FB-2AH4 cannot be used together with the FB-4AJ16"},
        {"temperature:\n  modules: [FB-2AX4]\n", 3, 13, "unknown module 'FB-2AX4'"},
        {"temperature:\n  modules: FB-2AK4\n", 3, 12, "expected a list"},
    };
    for (const Case& c : cases) {
        testing::expect_config_error(
            testing::config_failure(
                [&] { config::parse_config("profile: fb\n" + std::string(c.text), "fb.yaml"); }),
            "fb.yaml", c.line, c.col, c.needle);
    }
}

// docs/profile-fb.md, "Temperature modules": each accepted name becomes its module, in chain
// order: an FB-2A…4 by its Tp code with 4 points, an FB-4AJ/K multiplexed with its points.
TEST(FbTemperatureModules, Accepted) {
    const fb::TemperatureConfig slim =
        fb::settings_of(
            config::parse_config(
                "profile: fb\ntemperature: {modules: [FB-2AK4, FB-2AT4-3, FB-2AH4-3]}\n",
                "fb.yaml"))
            ->temperature;
    ASSERT_EQ(slim.modules.size(), 3u);
    const int tp[] = {0, 5, 4};
    for (std::size_t i = 0; i < 3; ++i) {
        EXPECT_FALSE(slim.modules[i].multiplexed) << i;
        EXPECT_EQ(slim.modules[i].sensor, tp[i]) << i;
        EXPECT_EQ(slim.modules[i].points, 4) << i;
    }
    EXPECT_EQ(slim.modules[1].name, "FB-2AT4-3");
    EXPECT_EQ(fb::declared_at(slim.modules[1]), "fb.yaml:2:34");
    struct Case {
        const char* name;
        int sensor, points;
    };
    for (const Case& c : {Case{"FB-4AJ12", 1, 12}, Case{"FB-4AJ16", 1, 16}, Case{"FB-4AK18", 0, 18},
                          Case{"FB-4AK24", 0, 24}}) {
        const fb::TemperatureConfig t =
            fb::settings_of(config::parse_config("profile: fb\ntemperature: {modules: [" +
                                                     std::string(c.name) + "]}\n",
                                                 "fb.yaml"))
                ->temperature;
        ASSERT_EQ(t.modules.size(), 1u) << c.name;
        EXPECT_EQ(t.modules[0].name, c.name);
        EXPECT_TRUE(t.modules[0].multiplexed) << c.name;
        EXPECT_EQ(t.modules[0].sensor, c.sensor) << c.name;
        EXPECT_EQ(t.modules[0].points, c.points) << c.name;
        EXPECT_EQ(fb::multiplexed_module(t.modules), &t.modules[0]) << c.name;
    }
}

}  // namespace
}  // namespace plcemu::profiles
