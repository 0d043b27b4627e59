// The VIGOR VB profile (docs/profile-vb.md): octal X/Y and the TN/CN/TS/CS spelling, K/H
// constants, the device areas and their holes, retentive defaults, the special relays and
// registers (clocks, initial pulse, scan time in 0.1 ms, calendar), the default Modbus map row by
// row, and CNT's direction relays M9200–M9234.

#include <gtest/gtest.h>

#include <chrono>
#include <string>
#include <vector>

#include "plcemu/config/config.hpp"
#include "plcemu/daemon/plc.hpp"
#include "plcemu/modbus/address_map.hpp"
#include "support/config_errors.hpp"
#include "support/plc_rig.hpp"
#include "support/profiles.hpp"
#include "support/wire.hpp"

namespace plcemu::profiles {
namespace {

using image::Area;
using image::Device;
using image::Range;
using modbus::Table;

const Profile& vb() { return testing::profile("vb"); }
const image::Naming& naming() { return vb().naming(); }

// A VB PLC built from config text (the profile line is added).
struct Rig : testing::WiredPlcRig {
    explicit Rig(const std::string& yaml = "")
        : WiredPlcRig("profile: vb\n" + yaml, "vb.yaml") {}
};

// ---- identity

TEST(VbProfile, Identity) {
    EXPECT_EQ(vb().name(), "vb");
    EXPECT_EQ(vb().title(), "VIGOR VB");
    EXPECT_EQ(vb().family(), 2u);
    EXPECT_EQ(vb().vendor(), "VIGOR");
    EXPECT_EQ(vb().default_model(), "VB2-32M");
    EXPECT_EQ(vb().max_station(), 247);
    // modules:, mbus: and file_registers: (docs/profile-vb.md), no FBs temperature: section.
    EXPECT_EQ(vb().sections(),
              (std::vector<std::string_view>{"modules", "mbus", "file_registers"}));
    EXPECT_EQ(vb().drive_full_scale(), 1000);
}

// docs/profile-vb.md, "Identity": V[BH][0-9]?-[0-9]+M[A-Z]*.
TEST(VbProfile, ModelGrammar) {
    for (const char* ok : {"VB2-32M", "VB-14MR", "VH-40MT", "VB1-24MRD", "VH2-60M"}) {
        EXPECT_TRUE(vb().valid_model(ok)) << ok;
    }
    for (const char* bad : {"", "VB", "VB2-", "VB2-M", "VB22-32M", "VC-32M", "VB2-32", "VB2-32Mr",
                            "vb2-32M", "VB2_32M", "VB2-32M ", "FBs-24MC"}) {
        EXPECT_FALSE(vb().valid_model(bad)) << bad;
    }
}

// ---- naming: octal X/Y, TN/CN/TS/CS, K/H constants

TEST(VbNaming, XAndYAreOctal) {
    EXPECT_EQ(naming().parse_device("X17"), (Device{Area::X, 15, false}));
    EXPECT_EQ(naming().parse_device("Y10"), (Device{Area::Y, 8, false}));
    EXPECT_EQ(naming().parse_device("y377"), (Device{Area::Y, 255, false}));
    EXPECT_FALSE(naming().parse_device("X8"));
    EXPECT_FALSE(naming().parse_device("Y19"));
    EXPECT_EQ(naming().format_device(Area::X, 8), "X10");
    EXPECT_EQ(naming().format_range({Area::Y, 0, 256}), "Y0-Y377");
    EXPECT_EQ(naming().parse_range("Y10-Y17"), (Range{Area::Y, 8, 8}));
    EXPECT_EQ(naming().parse_device("WY10"), (Device{Area::Y, 8, true}));
    // The other areas are decimal.
    EXPECT_EQ(naming().parse_device("M19"), (Device{Area::M, 19, false}));
    EXPECT_EQ(naming().format_device(Area::D, 9010), "D9010");
}

// A refused X8 or Y19 says why: the config loader and the program's operands add it.
TEST(VbNaming, WhyNotNamesTheOctalAreas) {
    const std::string octal = "X and Y are numbered in octal: 7 is followed by 10";
    EXPECT_EQ(naming().why_not("X8"), octal);
    EXPECT_EQ(naming().why_not("y19"), octal);
    EXPECT_EQ(naming().why_not("Y10-Y18"), octal);
    for (const char* other : {"X17", "M8", "D9", "Z9", ""}) {
        EXPECT_EQ(naming().why_not(other), "") << other;
    }
    EXPECT_EQ(testing::profile("fbs").naming().why_not("X8"), "");  // decimal there
}

TEST(VbNaming, TimerAndCounterSpelling) {
    EXPECT_EQ(naming().parse_device("TN5"), (Device{Area::TV, 5, false}));
    EXPECT_EQ(naming().parse_device("CN199"), (Device{Area::CV, 199, false}));
    EXPECT_EQ(naming().parse_device("CN200"), (Device{Area::CV, 200, false}));
    EXPECT_EQ(naming().parse_device("CN201"), (Device{Area::CV, 202, false}));  // 2 words each
    EXPECT_EQ(naming().parse_device("CN255"), (Device{Area::CV, 310, false}));
    EXPECT_EQ(naming().parse_device("TS3"), (Device{Area::T, 3, false}));
    EXPECT_EQ(naming().parse_device("T3"), (Device{Area::T, 3, false}));
    EXPECT_EQ(naming().parse_device("CS4"), (Device{Area::C, 4, false}));
    EXPECT_EQ(naming().parse_device("S4"), (Device{Area::S, 4, false}));
    EXPECT_EQ(naming().format_device(Area::CV, 202), "CN201");
    EXPECT_EQ(naming().format_range({Area::CV, 200, 112}), "CN200-CN255");
    EXPECT_EQ(naming().format_range({Area::TV, 0, 256}), "TN0-TN255");
    EXPECT_EQ(naming().parse_range("CN254-CN255"), (Range{Area::CV, 308, 4}));
    // No R area, and none of the FBs spellings.
    for (const char* bad : {"R0", "TMR0", "CTR0", "Z0", "V0"}) {
        EXPECT_FALSE(naming().parse_device(bad)) << bad;
    }
    EXPECT_EQ(naming().area_name(Area::R), "");
}

// The VB manual writes constants K100 and H0011 (VB manual FNC88, example).
TEST(VbNaming, KAndHConstants) {
    long long v = 0;
    EXPECT_TRUE(naming().parse_integer("K100", v));
    EXPECT_EQ(v, 100);
    EXPECT_TRUE(naming().parse_integer("K-5", v));
    EXPECT_EQ(v, -5);
    EXPECT_TRUE(naming().parse_integer("H0011", v));
    EXPECT_EQ(v, 0x11);
    EXPECT_TRUE(naming().parse_integer("hFF", v));
    EXPECT_EQ(v, 0xFF);
    EXPECT_TRUE(naming().parse_integer("0x1F", v));
    EXPECT_EQ(v, 31);
    EXPECT_TRUE(naming().parse_integer("1Fh", v));
    EXPECT_EQ(v, 31);
    EXPECT_FALSE(naming().parse_integer("H", v));
    EXPECT_FALSE(naming().parse_integer("HG1", v));
    EXPECT_FALSE(naming().parse_integer("K1F", v));
}

// ---- layout: sizes, holes, retentive defaults

TEST(VbLayout, AreasAndHoles) {
    const image::Layout l = vb().layout();
    EXPECT_EQ(l.family, 2u);
    EXPECT_EQ(l.size_of(Area::X), 256u);
    EXPECT_EQ(l.size_of(Area::Y), 256u);
    EXPECT_EQ(l.size_of(Area::S), 1000u);
    EXPECT_EQ(l.size_of(Area::T), 256u);
    EXPECT_EQ(l.size_of(Area::C), 256u);
    EXPECT_EQ(l.size_of(Area::R), 0u);
    EXPECT_EQ(l.size_of(Area::TV), 256u);
    EXPECT_EQ(l.size_of(Area::CV), 312u);
    EXPECT_TRUE(l.contains({Area::M, 0, 3072}));
    EXPECT_TRUE(l.contains({Area::M, 9000, 256}));
    EXPECT_FALSE(l.contains({Area::M, 3071, 2}));
    EXPECT_FALSE(l.contains({Area::M, 8999, 1}));
    EXPECT_FALSE(l.contains({Area::M, 9255, 2}));
    EXPECT_TRUE(l.contains({Area::D, 0, 8000}));
    EXPECT_TRUE(l.contains({Area::D, 9000, 256}));
    EXPECT_FALSE(l.contains({Area::D, 7999, 2}));
    EXPECT_FALSE(l.contains({Area::D, 8500, 1}));
    EXPECT_FALSE(l.contains({Area::R, 0, 1}));
}

bool retentive(const image::Layout& l, Area a, std::uint32_t i) {
    for (const auto& r : l.retentive) {
        if (r.contains({a, i, 1})) return true;
    }
    return false;
}

// docs/profile-vb.md, "Device areas": FX2N's latched ranges.
TEST(VbLayout, RetentiveDefaults) {
    const image::Layout l = vb().layout();
    struct Edge {
        Area area;
        std::uint32_t first, last;
    };
    for (const Edge& e :
         {Edge{Area::M, 500, 3071}, Edge{Area::S, 500, 999}, Edge{Area::T, 246, 255},
          Edge{Area::TV, 246, 255}, Edge{Area::C, 100, 199}, Edge{Area::CV, 100, 199},
          Edge{Area::C, 220, 255}, Edge{Area::CV, 240, 311}, Edge{Area::D, 200, 7999}}) {
        SCOPED_TRACE(std::string(image::area_name(e.area)) + std::to_string(e.first));
        EXPECT_FALSE(retentive(l, e.area, e.first - 1));
        EXPECT_TRUE(retentive(l, e.area, e.first));
        EXPECT_TRUE(retentive(l, e.area, e.last));
        if (e.last + 1 < l.size_of(e.area)) {
            EXPECT_FALSE(retentive(l, e.area, e.last + 1));
        }
    }
    // C200–C219 (words 200–239) are not; the specials are not.
    EXPECT_FALSE(retentive(l, Area::CV, 239));
    EXPECT_FALSE(retentive(l, Area::M, 9000));
    EXPECT_FALSE(retentive(l, Area::D, 9000));
}

// ---- specials

TEST(VbSpecials, RunOffAndInitialPulse) {
    Rig rig;
    rig.scan();
    EXPECT_TRUE(rig.m(9000));
    EXPECT_FALSE(rig.m(9001));
    EXPECT_TRUE(rig.m(9002));  // first scan
    EXPECT_FALSE(rig.m(9003));
    rig.scan();
    EXPECT_FALSE(rig.m(9002));
    EXPECT_TRUE(rig.m(9003));
    rig.plc.image().set_bit(Area::M, 9001, true);  // the program cannot keep it ON
    rig.scan(1000);
    EXPECT_TRUE(rig.m(9000));
    EXPECT_FALSE(rig.m(9001));
    EXPECT_FALSE(rig.m(9002));
    EXPECT_TRUE(rig.m(9003));
}

// M9011–M9014: ON for the first half of each period of simulated time; a clock whose half
// period is shorter than the scan toggles every scan (docs/profile-vb.md, "Special relays and
// registers").
TEST(VbSpecials, ClocksOfSimulatedTime) {
    Rig rig;  // scan_ms 10
    for (std::uint64_t k = 0; k < 7000; ++k) {
        rig.scan();  // scan k ran at k × 10 ms
        const std::uint64_t ms = k * 10;
        ASSERT_EQ(rig.m(9011), k % 2 == 0) << k;
        ASSERT_EQ(rig.m(9012), (ms / 50) % 2 == 0) << k;
        ASSERT_EQ(rig.m(9013), (ms / 500) % 2 == 0) << k;
        ASSERT_EQ(rig.m(9014), (ms / 30000) % 2 == 0) << k;
    }
}

TEST(VbSpecials, TenMillisecondClockWithAFastScan) {
    Rig rig("scan_ms: 1\n");
    for (std::uint64_t k = 0; k < 40; ++k) {
        rig.scan();
        ASSERT_EQ(rig.m(9011), (k / 5) % 2 == 0) << k;
    }
}

// D9010–D9012: current, minimum, maximum scan time in 0.1 ms, the simulated scan period.
TEST(VbSpecials, ScanTimeInTenthsOfAMillisecond) {
    for (int ms : {1, 10, 25, 1000}) {
        Rig rig("scan_ms: " + std::to_string(ms) + "\n");
        rig.scan(3);
        const auto t = static_cast<std::uint16_t>(ms * 10);
        EXPECT_EQ(rig.d(9010), t) << ms;
        EXPECT_EQ(rig.d(9011), t) << ms;
        EXPECT_EQ(rig.d(9012), t) << ms;
    }
}

TEST(VbSpecials, MinimumAndMaximumFollowTheIntervals) {
    Rig rig;
    auto& e = rig.plc.engine();
    e.step(std::chrono::milliseconds(0), {});
    e.step(std::chrono::milliseconds(10), {});
    e.step(std::chrono::milliseconds(35), {});  // a late scan: 25 ms
    e.step(std::chrono::milliseconds(40), {});  // then 5 ms
    EXPECT_EQ(rig.d(9010), 50);
    EXPECT_EQ(rig.d(9011), 50);
    EXPECT_EQ(rig.d(9012), 250);
}

// D9013–D9019: second, minute, hour, day, month, year (two digits), weekday.
TEST(VbSpecials, Calendar) {
    Rig rig;
    rig.scan(1, engine::Calendar{12, 34, 5, 6, 7, 2031, 4});
    const std::vector<std::uint16_t> want{12, 34, 5, 6, 7, 31, 4};
    for (std::uint32_t i = 0; i < 7; ++i) EXPECT_EQ(rig.d(9013 + i), want[i]) << i;
}

// Power-up: M9067, D9067, D9069 cleared, D9129 0; presets still win (they come after).
TEST(VbSpecials, PowerUpValues) {
    const config::Config cfg = config::parse_config("profile: vb\n", "vb.yaml");
    image::Image img(vb().layout());
    img.set_bit(Area::M, 9067, true);
    img.set_word(Area::D, 9067, 6730);
    img.set_word(Area::D, 9069, 3);
    img.set_word(Area::D, 9129, 50);
    vb().specials(cfg)->power_up(img, 1);
    EXPECT_FALSE(img.bit(Area::M, 9067));
    EXPECT_EQ(img.word(Area::D, 9067), 0);
    EXPECT_EQ(img.word(Area::D, 9069), 0);
    EXPECT_EQ(img.word(Area::D, 9129), 0);

    Rig rig("init: {D9129: 50}\n");
    EXPECT_EQ(rig.d(9129), 50);
}

// The VB has no station register (docs/profile-vb.md, "Station"): the configured station stays
// when a master writes the FATEK station request (55h in the high byte, R4055 on an FBs) to the
// VB's registers at that address (D4055, plain latched storage) and in its special block
// (D9055 = register 8055, plain storage). Both writes land; neither moves the station.
TEST(VbSpecials, StationStays) {
    Rig rig("station: 247\nsimulator: {unit: 0}\n");
    for (const std::uint16_t addr : {std::uint16_t{4055}, std::uint16_t{8055}}) {
        EXPECT_EQ(rig.wire.tcp(247, testing::write_single_pdu(0x06, addr, 0x5505)),
                  testing::write_single_pdu(0x06, addr, 0x5505))
            << addr;
    }
    rig.scan(3);
    EXPECT_EQ(rig.d(4055), 0x5505);
    EXPECT_EQ(rig.d(9055), 0x5505);
    EXPECT_EQ(rig.plc.engine().station(), 247);
    EXPECT_EQ(testing::reply_words(rig.wire.tcp(247, testing::read_pdu(0x03, 8055, 1))),
              std::vector<std::uint16_t>{0x5505});
}

// ---- CNT with the VB's direction relays

TEST(VbCounters, M9200ToM9234SetTheDirectionOf32BitCounters) {
    Rig rig(
        "program:\n"
        "  - CNT: {en: M0, c: C200, k: K-2}\n"
        "  - CNT: {en: M0, c: C234, k: K5}\n"
        "  - CNT: {en: M9013, c: C1, k: K32767}\n");
    auto pulse = [&] {
        rig.plc.image().set_bit(Area::M, 0, true);
        rig.scan();
        rig.plc.image().set_bit(Area::M, 0, false);
        rig.scan();
    };
    rig.plc.image().set_bit(Area::M, 9200, true);  // C200 down
    pulse();
    pulse();
    auto value = [&](std::uint32_t w) {
        return static_cast<std::int32_t>(rig.plc.image().word(Area::CV, w) |
                                         rig.plc.image().word(Area::CV, w + 1) << 16);
    };
    EXPECT_EQ(value(200), -2);
    EXPECT_TRUE(rig.plc.image().bit(Area::C, 200));
    EXPECT_EQ(value(naming().counter_word(234)), 2);  // M9234 OFF: up
    // C1 counts the 1 s clock: 60 s after the start (scans 0–5999 and 4 above) it read 60.
    rig.scan(6000 - 4);
    EXPECT_EQ(rig.plc.image().word(Area::CV, 1), 60);
}

// ---- the default Modbus map

struct ManualRow {
    Table table;
    std::uint16_t first;  // wire address
    std::uint16_t count;
    Area area;
    std::uint32_t device;  // first device index
    const char* label;
};

// FX3U MODBUS manual (JY997D26201) §9.3 with the VB's devices (docs/profile-vb.md, "Modbus map"),
// written down independently of the code's table.
const std::vector<ManualRow>& manual_rows() {
    static const std::vector<ManualRow> rows = [] {
        std::vector<ManualRow> r;
        const ManualRow bits[] = {
            {Table::Coils, 0x0000, 3072, Area::M, 0, "M0-M3071"},
            {Table::Coils, 0x1E00, 256, Area::M, 9000, "M9000-M9255"},
            {Table::Coils, 0x2000, 1000, Area::S, 0, "S0-S999"},
            {Table::Coils, 0x3000, 256, Area::T, 0, "T0-T255"},
            {Table::Coils, 0x3200, 256, Area::C, 0, "C0-C255"},
            {Table::Coils, 0x3300, 256, Area::Y, 0, "Y0-Y377"},
        };
        for (auto b : bits) r.push_back(b);
        for (auto b : bits) {
            b.table = Table::DiscreteInputs;
            r.push_back(b);
        }
        r.push_back({Table::DiscreteInputs, 0x3400, 256, Area::X, 0, "X0-X377"});
        const ManualRow words[] = {
            {Table::HoldingRegisters, 0, 8000, Area::D, 0, "D0-D7999"},
            {Table::HoldingRegisters, 8000, 256, Area::D, 9000, "D9000-D9255"},
            {Table::HoldingRegisters, 9000, 256, Area::TV, 0, "TN0-TN255"},
            {Table::HoldingRegisters, 9500, 200, Area::CV, 0, "CN0-CN199"},
            {Table::HoldingRegisters, 9700, 112, Area::CV, 200, "CN200-CN255"},
        };
        for (auto w : words) r.push_back(w);
        for (auto w : words) {
            w.table = Table::InputRegisters;
            r.push_back(w);
        }
        return r;
    }();
    return rows;
}

TEST(VbMap, RowsAreTheTable) {
    const auto& rows = vb().map().rows();
    ASSERT_EQ(rows.size(), manual_rows().size());
    for (std::size_t i = 0; i < rows.size(); ++i) {
        const auto& want = manual_rows()[i];
        SCOPED_TRACE(want.label);
        EXPECT_EQ(rows[i].table, want.table);
        EXPECT_EQ(rows[i].wire_start, want.first);
        EXPECT_EQ(rows[i].count, want.count);
        const std::uint32_t n = want.area == Area::CV && want.device == 200 ? 112 : want.count;
        EXPECT_EQ(rows[i].devices, (Range{want.area, want.device, n}));
        EXPECT_EQ(rows[i].label.rfind(want.label, 0), 0u) << rows[i].label;
        EXPECT_FALSE(rows[i].packed);
        const bool bit = want.table == Table::Coils || want.table == Table::DiscreteInputs;
        const bool write = want.table == Table::Coils || want.table == Table::HoldingRegisters;
        EXPECT_EQ(rows[i].codes,
                  bit ? (write ? "01 05 15" : "02") : (write ? "03 06 16 22 23" : "04"));
    }
}

TEST(VbMap, FirstAndLastOfEveryRowResolveToTheirDevice) {
    const image::Image img(vb().layout());
    for (const auto& row : manual_rows()) {
        SCOPED_TRACE(row.label);
        const auto first = vb().map().resolve(img, row.table, row.first, 1);
        ASSERT_EQ(first.status, modbus::Status::Ok);
        EXPECT_EQ(first.devices, (Range{row.area, row.device, 1}));
        const auto last = vb().map().resolve(
            img, row.table, static_cast<std::uint16_t>(row.first + row.count - 1), 1);
        ASSERT_EQ(last.status, modbus::Status::Ok);
        EXPECT_EQ(last.devices, (Range{row.area, row.device + row.count - 1u, 1}));
    }
}

TEST(VbMap, GapsAreIllegalAddresses) {
    const image::Image img(vb().layout());
    struct Gap {
        Table table;
        std::uint16_t addr;
    };
    for (const Gap& g :
         {Gap{Table::Coils, 0x0C00}, Gap{Table::Coils, 0x1DFF}, Gap{Table::Coils, 0x1F00},
          Gap{Table::Coils, 0x23E8}, Gap{Table::Coils, 0x3100}, Gap{Table::Coils, 0x3400},
          Gap{Table::DiscreteInputs, 0x3500}, Gap{Table::HoldingRegisters, 8256},
          Gap{Table::HoldingRegisters, 8999}, Gap{Table::HoldingRegisters, 9256},
          Gap{Table::HoldingRegisters, 9499}, Gap{Table::HoldingRegisters, 9812},
          Gap{Table::InputRegisters, 9812}, Gap{Table::InputRegisters, 65535}}) {
        EXPECT_EQ(vb().map().resolve(img, g.table, g.addr, 1).status,
                  modbus::Status::IllegalDataAddress)
            << int(g.table) << " " << g.addr;
    }
    // CN199 and CN200 continue each other.
    EXPECT_EQ(vb().map().resolve(img, Table::HoldingRegisters, 9699, 3).devices,
              (Range{Area::CV, 199, 3}));
}

TEST(VbMap, ReadOnlyItems) {
    const auto& ro = vb().map().read_only();
    const std::vector<Range> want{
        {Area::X, 0, 256}, {Area::M, 9000, 4}, {Area::M, 9011, 4}, {Area::D, 9010, 3}};
    EXPECT_EQ(ro, want);
}

// Through the dispatcher: D9129 at 8129, D9010 read-only, X10 as discrete input 3408h, no X
// among the coils, C200 low word first, FC02/FC04.
TEST(VbMap, ThroughTheDispatcher) {
    Rig rig("init: {X10: 1, D9129: 7, CN200: [0x5678, 0x1234], D5: 55}\n");
    rig.scan(2);
    auto& w = rig.wire;
    EXPECT_EQ(testing::reply_words(w.tcp(1, testing::read_pdu(0x03, 8129, 1))),
              std::vector<std::uint16_t>{7});
    EXPECT_EQ(testing::reply_words(w.tcp(1, testing::read_pdu(0x03, 8010, 3))),
              (std::vector<std::uint16_t>{100, 100, 100}));
    EXPECT_EQ(testing::exception_of(w.tcp(1, testing::write_single_pdu(0x06, 8010, 1))), 0x02);
    EXPECT_EQ(testing::reply_bits(w.tcp(1, testing::read_pdu(0x02, 0x3408, 1)), 1),
              std::vector<bool>{true});
    EXPECT_EQ(testing::exception_of(w.tcp(1, testing::read_pdu(0x01, 0x3400, 1))), 0x02);
    EXPECT_EQ(testing::reply_words(w.tcp(1, testing::read_pdu(0x03, 9700, 2))),
              (std::vector<std::uint16_t>{0x5678, 0x1234}));
    EXPECT_EQ(testing::reply_words(w.tcp(1, testing::read_pdu(0x04, 5, 1))),
              std::vector<std::uint16_t>{55});
    EXPECT_EQ(testing::reply_bits(w.tcp(1, testing::read_pdu(0x02, 0x1E00, 4)), 4),
              (std::vector<bool>{true, false, false, true}));
    // FC04 and FC02 are reads only: no write function reaches them.
    EXPECT_EQ(testing::exception_of(w.tcp(1, testing::write_single_pdu(0x05, 0x3408, 0))), 0x02);
}

// modbus.map replaces the default: WM0 packed bits, access ro.
TEST(VbMap, ConfigMapReplacesTheDefault) {
    Rig rig(
        "modbus:\n"
        "  map:\n"
        "    - {table: holding, start: 0, device: D0, count: 100}\n"
        "    - {table: holding, start: 0x2478, device: WM0, count: 4}\n"
        "    - {table: coils, start: 0x3300, device: Y0, count: 256, access: ro}\n");
    auto& w = rig.wire;
    EXPECT_EQ(testing::exception_of(w.tcp(1, testing::read_pdu(0x03, 8000, 1))), 0x02);
    EXPECT_EQ(testing::exception_of(w.tcp(1, testing::write_single_pdu(0x06, 0x2478, 0x8001))), 0);
    EXPECT_TRUE(rig.m(0));
    EXPECT_TRUE(rig.m(15));
    EXPECT_FALSE(rig.m(1));
    rig.plc.image().set_bit(Area::M, 17, true);
    EXPECT_EQ(testing::reply_words(w.tcp(1, testing::read_pdu(0x03, 0x2479, 1))),
              std::vector<std::uint16_t>{0x0002});
    EXPECT_EQ(testing::exception_of(w.tcp(1, testing::write_single_pdu(0x05, 0x3300, 0xFF00))),
              0x02);
    EXPECT_FALSE(rig.plc.image().bit(Area::Y, 0));
    // A table no row serves is not served at all.
    EXPECT_EQ(testing::exception_of(w.tcp(1, testing::read_pdu(0x02, 0, 1))), 0x01);
}

TEST(VbConfig, ErrorsNameLineAndColumn) {
    struct Case {
        std::string text;
        int line, col;
        std::string needle;
    };
    for (const Case& c : std::vector<Case>{
             {"init:\n  X8: 1\n", 3, 3, "octal"},
             {"temperature: {table: D0}\n", 2, 14, "profile vb has no such subsystem"},
             {"model: VB2-32\n", 2, 8, "VIGOR model"},
             {"station: 248\n", 2, 10, "1..247"},
             {"modbus:\n  map:\n    - {table: holding, start: 0, device: M0, count: 1}\n", 4, 42,
              "WM0"},
         }) {
        SCOPED_TRACE(c.text);
        testing::expect_config_error(testing::config_failure([&] {
                                         config::parse_config("profile: vb\n" + c.text, "v.yaml");
                                     }),
                                     "v.yaml", c.line, c.col, c.needle);
    }
    // A program's operand in octal X/Y with an 8 or 9 is refused at its position, saying why.
    for (const char* text : {"program:\n  - MOV: {en: X8, s: K1, d: D0}\n",
                             "program:\n  - CNT: {en: Y19, c: C0, k: K1}\n"}) {
        SCOPED_TRACE(text);
        testing::expect_config_error(testing::config_failure([&] { Rig rig(text); }), "vb.yaml", 3,
                                     15, ".en: expected a bit device");
        testing::expect_config_error(testing::config_failure([&] { Rig rig(text); }), "vb.yaml", 3,
                                     15, "(X and Y are numbered in octal: 7 is followed by 10)");
    }
    // Devices that do not exist are refused when the PLC is built.
    for (const char* text : {"init: {D8000: 1}\n", "init: {M5000: 1}\n"}) {
        SCOPED_TRACE(text);
        testing::expect_config_error(testing::config_failure([&] { Rig rig(text); }), "vb.yaml", 2,
                                     8, "does not exist");
    }
}

}  // namespace
}  // namespace plcemu::profiles
