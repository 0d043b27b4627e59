// The rows of `plcemud --export-tags`: what the program, the profile, the presets and the
// simulator unit describe, each at the address that serves it.

#include "daemon/export_tags.hpp"

#include <gtest/gtest.h>

#include <set>
#include <sstream>
#include <string>

namespace plcemu::daemon {
namespace {

using modbus::Table;

TagExport rows_of(const std::string& yaml) {
    return export_tags(config::parse_config(yaml, "t.yaml"));
}

const TagRow& row(const TagExport& e, const std::string& name) {
    for (const auto& r : e.rows) {
        if (r.name == name) return r;
    }
    ADD_FAILURE() << "no row " << name;
    static const TagRow none;
    return none;
}

std::string written(const std::vector<TagRow>& rows, bool json) {
    std::ostringstream out;
    write_tags(out, rows, json);
    return out.str();
}

bool has(const TagRow& r, const std::string& text) {
    return r.description.find(text) != std::string::npos;
}

const char* kFbsTemperature =
    "profile: fbs\n"
    "temperature: {table: R5000, modules: [TC6:K, RTD6:PT100_DIN]}\n"
    "init:\n"
    "  R5000: [0xA556, 2, 10000, 20000, 0x0101, 0x0002]\n"
    "program:\n"
    "  - MOV: {en: M1926, s: WM800, d: R4012}\n"
    "  - TPCTL: {en: M0, hc: 1, md: 0, sn: 0, zn: 10, yn: Y30, sv: R100, os: R110, pr: R120,\n"
    "           ir: R130, dr: R140, or: R200, wr: R300, err: M100, alm: M101}\n";

TEST(ExportTags, OperandsOfTheProgramWithTheirSpans) {
    const TagExport e = rows_of(kFbsTemperature);
    const TagRow& sv = row(e, "R100");
    EXPECT_EQ(sv.device, "R100");
    EXPECT_EQ(sv.unit, 1);
    EXPECT_EQ(sv.table, Table::HoldingRegisters);
    EXPECT_EQ(sv.address, 100);
    EXPECT_EQ(sv.type, "int16");
    EXPECT_TRUE(sv.writable);
    EXPECT_TRUE(has(sv, "TPCTL sv, program entry 2 (t.yaml:7:63) [0]")) << sv.description;
    EXPECT_TRUE(has(row(e, "R109"), "TPCTL sv, program entry 2 (t.yaml:7:63) [9]"));
    EXPECT_EQ(row(e, "R110").address, 110);
    // The ten Y outputs, coils 30-39, and WM800 as the sixteen relays it reads.
    EXPECT_EQ(row(e, "Y39").table, Table::Coils);
    EXPECT_EQ(row(e, "Y39").address, 39);
    EXPECT_EQ(row(e, "Y39").type, "bool");
    EXPECT_TRUE(has(row(e, "Y30"), "heater output of plant channel 0"));
    EXPECT_EQ(row(e, "M815").address, 2815);
    EXPECT_TRUE(has(row(e, "M815"), "MOV s, program entry 1"));
    EXPECT_EQ(row(e, "M101").address, 2101);
}

// A program written as the family's instruction list names each instruction by its step, the
// number --print-program prints beside it, not by its place among YAML entries.
TEST(ExportTags, AListingNamesItsInstructionsByStep) {
    const TagExport e = rows_of(
        "profile: fbs\n"
        "program:\n"
        "  il:\n"
        "    - ORG M1926\n"
        "    - FUN8 MOV S:WM800 D:R4012\n"
        "    - ORG M0\n"
        "    - OUT Y0\n"
        "    - FUN8 MOV S:R300 D:WM400\n");
    EXPECT_TRUE(has(row(e, "M815"), "MOV s, step 2 (t.yaml:5:18)")) << row(e, "M815").description;
    EXPECT_TRUE(has(row(e, "R300"), "MOV s, step 5 (t.yaml:8:18)")) << row(e, "R300").description;
    for (const auto& r : e.rows) EXPECT_FALSE(has(r, "program entry")) << r.name;
}

TEST(ExportTags, WorkingBlocksAsTheInstructionDescribesThem) {
    const TagExport e = rows_of(kFbsTemperature);
    const TagRow& wr0 = row(e, "R300");
    EXPECT_EQ(wr0.type, "uint16");
    EXPECT_TRUE(has(wr0, "TPCTL WR+0 in-zone bits, points 0-15")) << wr0.description;
    EXPECT_TRUE(has(row(e, "R308"), "TPCTL WR+8 heater-open bits, points 16-31"));
    EXPECT_TRUE(has(row(e, "R203"), "TPCTL point 3 (channel 3) PID output, 0-16383"));
    EXPECT_TRUE(has(row(e, "Y39"), "TPCTL point 9 (channel 9) PWM output"));
}

TEST(ExportTags, TemperatureTableReadingsAndWorkingRegisters) {
    const TagExport e = rows_of(kFbsTemperature);
    EXPECT_TRUE(has(row(e, "R5000"), "temperature table SR+0: A556h"));
    EXPECT_TRUE(has(row(e, "R5000"), "preset by init: (t.yaml:4:3) [0]"));
    EXPECT_TRUE(has(row(e, "R5005"), "module 2, name code"));
    // TC6 + RTD6: twelve readings from R0 (SR+2 = 10000), signed.
    EXPECT_EQ(row(e, "R11").type, "int16");
    EXPECT_TRUE(has(row(e, "R11"), "temperature reading, channel 11"));
    for (const auto& r : e.rows) EXPECT_FALSE(has(r, "channel 12,")) << r.name;
    // WR at D0 (SR+3 = 20000): 4 + 4·2 words, D0 at holding register 6000.
    EXPECT_EQ(row(e, "D0").address, 6000);
    EXPECT_TRUE(has(row(e, "D11"), "WR+11: module 2 channel being converted"));
    for (const auto& r : e.rows) EXPECT_NE(r.name, "D12");
}

TEST(ExportTags, SpecialDevicesAndTheirAccess) {
    const TagExport e = rows_of(kFbsTemperature);
    const TagRow& run = row(e, "M1926");
    EXPECT_EQ(run.address, 3926);
    EXPECT_FALSE(run.writable);  // the map's read-only specials
    EXPECT_TRUE(has(run, "special relay: RUN"));
    EXPECT_TRUE(has(run, "MOV en, program entry 1"));
    EXPECT_FALSE(row(e, "R4136").writable);
    EXPECT_EQ(row(e, "R4136").type, "uint16");
    EXPECT_TRUE(row(e, "R4055").writable);
    EXPECT_TRUE(has(row(e, "R4134"), "calendar weekday"));
    EXPECT_TRUE(has(row(e, "R3968"), "Modbus map: A55Ah"));
}

TEST(ExportTags, SimulatorUnitRegisters) {
    const TagExport e = rows_of(kFbsTemperature);
    const TagRow& scale = row(e, "sim.time_scale");
    EXPECT_EQ(scale.unit, 247);
    EXPECT_EQ(scale.device, "");
    EXPECT_EQ(scale.address, 0);
    EXPECT_TRUE(scale.writable);
    const TagRow& t31 = row(e, "sim.ch31.true_temperature");
    EXPECT_EQ(t31.address, 100 + 10 * 31 + 6);
    EXPECT_EQ(t31.type, "int16");
    EXPECT_FALSE(t31.writable);
    EXPECT_TRUE(row(e, "sim.ch2.ambient").writable);
    // The PLC's rows first, then the unit's, each by table and address.
    EXPECT_EQ(e.rows.back().unit, 247);
    EXPECT_EQ(e.rows.front().unit, 1);
}

TEST(ExportTags, ReadOnlyGatewayAndNoSimulatorUnit) {
    const TagExport e = rows_of(
        "profile: fbs\nmodbus: {read_only: true}\nsimulator: {unit: 0}\n"
        "program:\n  - MOV: {en: M0, s: R1, d: R2}\n");
    for (const auto& r : e.rows) {
        EXPECT_FALSE(r.writable) << r.name;
        EXPECT_EQ(r.unit, 1) << r.name;
    }
    EXPECT_EQ(row(e, "R2").address, 2);
}

TEST(ExportTags, ThirtyTwoBitCountersAreOneInt32) {
    const TagExport e = rows_of(
        "profile: vb\nprogram:\n  - CNT: {en: M9013, c: C200, k: K10}\n"
        "  - CNT: {en: M9013, c: C201, k: K10}\n"
        "  - CNT: {en: M9013, c: C1, k: K10}\n");
    const TagRow& c200 = row(e, "CN200");
    EXPECT_EQ(c200.type, "int32");
    EXPECT_EQ(c200.table, Table::HoldingRegisters);
    EXPECT_EQ(c200.address, 9700);
    EXPECT_TRUE(has(c200, "low word at address, high word at address+1")) << c200.description;
    EXPECT_TRUE(has(c200, "CNT c value, program entry 1"));
    EXPECT_EQ(row(e, "CN201").address, 9702);
    EXPECT_EQ(row(e, "CN1").type, "int16");
    EXPECT_EQ(row(e, "CN1").address, 9501);
    // The contact, a coil at 3200h + n; the direction relay of C200.
    EXPECT_EQ(row(e, "C200").address, 0x3200 + 200);
    EXPECT_TRUE(has(row(e, "M9200"), "C200 counts down when ON"));
    EXPECT_FALSE(row(e, "M9000").writable);
    EXPECT_EQ(row(e, "M9000").address, 0x1E00);
    EXPECT_EQ(row(e, "D9010").address, 8010);
}

TEST(ExportTags, VbBlocksAndMbusTable) {
    const TagExport e = rows_of(
        "profile: vb\nmbus: {transport: tcp, tcp: {host: 127.0.0.1, port: 5021}}\n"
        "init:\n  D1000: 1\n  D1001: [5, 1, 10, 13, 2000, 4, 0]\n"
        "program:\n  - MBUS: {en: M0, s1: D1000, s2: D100}\n"
        "  - PID: {en: M1, s1: D300, s2: D301, s3: D400, d: D302}\n"
        "  - TPID: {en: M2, s1: D500, s2: D510, s3: D600, s4: D700, n: 2}\n");
    EXPECT_TRUE(has(row(e, "D1000"), "MBUS S1+0 number of transfer sets"));
    EXPECT_TRUE(has(row(e, "D1001"), "MBUS set 1 S1+1 slave station"));
    EXPECT_TRUE(has(row(e, "D2009"), "MBUS set 1 data read from station 5, MBUS at t.yaml:7:5 [9]"))
        << row(e, "D2009").description;
    EXPECT_EQ(row(e, "D103").type, "uint16");
    EXPECT_TRUE(has(row(e, "D103"), "MBUS S2+3 last exception code"));
    EXPECT_TRUE(has(row(e, "D400"), "PID S3+0 sampling time Ts, ms"));
    EXPECT_TRUE(has(row(e, "D302"), "PID D output MV"));
    EXPECT_TRUE(has(row(e, "D511"), "TPID S2+1 channel 1 present value PV"));
    EXPECT_TRUE(has(row(e, "D424"), "PID S3+24 alarm bits"));
    EXPECT_TRUE(has(row(e, "D620"), "TPID S3+20 channel 1 analog output"));
    EXPECT_TRUE(has(row(e, "D711"), "TPID S4+11 channel 1 deviation alarm setting"));
    for (const auto& r : e.rows) EXPECT_NE(r.name, "D630") << "two channels: S3 ends at D629";
}

TEST(ExportTags, DevicesTheMapLeavesOutAreReportedNotExported) {
    const TagExport e = rows_of(
        "profile: fbs\nmodbus:\n  map:\n"
        "    - {table: holding, start: 0, device: R0, count: 10}\n"
        "program:\n  - MOV: {en: M0, s: R1, d: R100}\n");
    EXPECT_EQ(row(e, "R1").address, 1);
    for (const auto& r : e.rows) EXPECT_NE(r.name, "R100");
    bool said = false;
    for (const auto& u : e.unreachable) said = said || u.rfind("R100: MOV d", 0) == 0;
    EXPECT_TRUE(said);
}

// Every row has a name of its own: a device's is the device (one PLC, no prefix), a simulator
// register's "sim.…" (5 clock registers and 8 per plant channel).
TEST(ExportTags, NamesAreUnique) {
    const TagExport e = rows_of(kFbsTemperature);
    std::set<std::string> names;
    std::size_t sim = 0;
    for (const auto& r : e.rows) {
        EXPECT_TRUE(names.insert(r.name).second) << r.name;
        if (r.device.empty()) {
            EXPECT_EQ(r.name.rfind("sim.", 0), 0u) << r.name;
            ++sim;
        } else {
            EXPECT_EQ(r.name, r.device);
        }
    }
    EXPECT_EQ(sim, 5u + 21u + 8u * 32u);  // time, communication faults, channels
    for (const char* n :
         {"Y30", "Y39", "M100", "R100", "R149", "R300", "R4012", "R5000", "R5005", "sim.time_scale",
          "sim.comm.delay_min_ms", "sim.comm.status", "sim.ch0.ambient", "sim.ch31.heater_power"}) {
        EXPECT_EQ(names.count(n), 1u) << n;
    }
    EXPECT_EQ(names.size(), e.rows.size());
}

TEST(ExportTags, CsvQuotesAndJsonEscapes) {
    std::vector<TagRow> rows{{"", "", "R1", "R1", 1, Table::HoldingRegisters, 1, "int16", true,
                              "a, \"quoted\" text", ""}};
    EXPECT_EQ(written(rows, false),
              "name,device,unit,table,address,address_1based,type,access,description\n"
              "R1,R1,1,holding_register,1,2,int16,read-write,\"a, \"\"quoted\"\" text\"\n");
    EXPECT_EQ(written(rows, true),
              "[\n  {\"name\": \"R1\", \"device\": \"R1\", \"unit\": 1, \"table\": "
              "\"holding_register\", \"address\": 1, \"address_1based\": 2, \"type\": \"int16\", "
              "\"access\": \"read-write\", \"description\": \"a, \\\"quoted\\\" text\"}\n]\n");
    EXPECT_EQ(written({}, true), "[]\n");
}

// docs/configuration.md, "Tag export": JSON text is UTF-8, so a byte that is not (a config file
// name's, quoted in a description) becomes U+FFFD; valid characters, U+202E too, pass as they are.
TEST(ExportTags, JsonReplacesBytesThatAreNotUtf8) {
    std::vector<TagRow> rows{{"", "", "R1", "R1", 1, Table::HoldingRegisters, 1, "int16", true,
                              "preset (caf\xe9\xff.yaml:2:3) \xc3\xa9 \xe2\x80\xae \xed\xa0\x80",
                              ""}};
    const std::string out = written(rows, true);
    EXPECT_NE(out.find("\"preset (caf\\ufffd\\ufffd.yaml:2:3) \xc3\xa9 \xe2\x80\xae "
                       "\\ufffd\\ufffd\\ufffd\""),
              std::string::npos)
        << out;
}

// docs/configuration.md, "Tag export": a `plcs:` config exports every PLC, each row naming its
// PLC (its name, else plcs[i], as --print-map --format csv does) and the listeners that reach it.
TEST(ExportTags, EveryPlcOfAPlcsConfigWithItsEndpointAndUnits) {
    const TagExport e = export_tags(config::parse_plcs(
        "plcs:\n"
        "  - {name: kiln, profile: fbs, simulator: {unit: 201},\n"
        "     modbus: {tcp: {bind: 127.0.0.1, port: 1502}, rtu: {device: /dev/ttyS9}},\n"
        "     program: [MOV: {en: M0, s: R1, d: R100}]}\n"
        "  - {name: press, profile: fbs, station: 2, simulator: {unit: 202},\n"
        "     modbus: {tcp: {bind: 127.0.0.1, port: 1502}},\n"
        "     program: [MOV: {en: M0, s: R1, d: R100}]}\n"
        "  - {profile: vb, modbus: {tcp: {bind: '::', port: 1503}}}\n"
        "  - {name: dryer, profile: fbs, program: [MOV: {en: M0, s: R1, d: R100}],\n"
        "     modbus: {tcp: {port: 1504}, map: [{table: holding, start: 0, device: R0, count: "
        "10}]}}\n",
        "p.yaml"));
    const TagRow& kiln = row(e, "kiln.R100");
    EXPECT_EQ(kiln.plc, "kiln");
    EXPECT_EQ(kiln.device, "R100");
    EXPECT_EQ(kiln.unit, 1);
    EXPECT_EQ(kiln.endpoint, "tcp:127.0.0.1:1502 rtu:/dev/ttyS9");
    const TagRow& press = row(e, "press.R100");
    EXPECT_EQ(press.unit, 2);
    EXPECT_EQ(press.address, 100);
    EXPECT_EQ(press.endpoint, "tcp:127.0.0.1:1502");
    EXPECT_EQ(row(e, "press.sim.freeze").unit, 202);
    EXPECT_EQ(row(e, "kiln.sim.ch0.ambient").unit, 201);
    const TagRow& vb = row(e, "plcs[2].sim.time_scale");
    EXPECT_EQ(vb.plc, "plcs[2]");
    EXPECT_EQ(vb.unit, 247);
    EXPECT_EQ(vb.endpoint, "tcp:[::]:1503");
    // In `plcs:` order, every row of a PLC before the next's.
    std::set<std::string> names;
    std::string last;
    std::set<std::string> done;
    for (const auto& r : e.rows) {
        EXPECT_TRUE(names.insert(r.name).second) << r.name;
        if (r.plc != last) {
            EXPECT_TRUE(done.insert(r.plc).second) << r.plc << " again after " << last;
            last = r.plc;
        }
    }
    EXPECT_EQ(done, (std::set<std::string>{"kiln", "press", "plcs[2]", "dryer"}));
    // What no address serves is said with the same prefix.
    bool said = false;
    for (const auto& u : e.unreachable) said = said || u.rfind("dryer.R100: MOV d", 0) == 0;
    EXPECT_TRUE(said);
    EXPECT_EQ(row(e, "dryer.R1").endpoint, "tcp:0.0.0.0:1504");
}

TEST(ExportTags, AFileHoldingOnePlcExportsWithoutPlcColumns) {
    const auto plcs = config::parse_plcs("profile: fbs\n", "one.yaml");
    const TagExport e = export_tags(plcs);
    EXPECT_EQ(e.rows.size(), export_tags(plcs.front()).rows.size());
    EXPECT_EQ(row(e, "R4136").plc, "");
    const std::string csv = written(e.rows, false);
    EXPECT_EQ(csv.substr(0, csv.find('\n')),
              "name,device,fatek,unit,table,address,address_1based,type,access,description");
}

TEST(ExportTags, PlcAndEndpointColumnsForRowsOfPlcsEntries) {
    std::vector<TagRow> rows{{"kiln", "tcp:127.0.0.1:1502", "kiln.R1", "R1", 1,
                              Table::HoldingRegisters, 1, "int16", true, "x", ""}};
    EXPECT_EQ(written(rows, false),
              "plc,name,device,endpoint,unit,table,address,address_1based,type,access,"
              "description\n"
              "kiln,kiln.R1,R1,tcp:127.0.0.1:1502,1,holding_register,1,2,int16,read-write,x\n");
    EXPECT_EQ(written(rows, true),
              "[\n  {\"plc\": \"kiln\", \"name\": \"kiln.R1\", \"device\": \"R1\", "
              "\"endpoint\": \"tcp:127.0.0.1:1502\", \"unit\": 1, \"table\": "
              "\"holding_register\", \"address\": 1, \"address_1based\": 2, \"type\": \"int16\", "
              "\"access\": \"read-write\", \"description\": \"x\"}\n]\n");
}

}  // namespace
}  // namespace plcemu::daemon

namespace plcemu::daemon {
namespace {

// docs/configuration.md, "Tag export": a family that speaks FATEK's protocol names each device
// as a FATEK master writes it too; the column is left out for one that does not.
TEST(ExportTags, FatekColumnForTheFamiliesThatSpeakIt) {
    const TagExport fbs = rows_of(
        "profile: fbs\ninit: {R100: 1, D10: 2, Y30: 1}\nprogram:\n"
        "  - MOV: {en: M1926, s: TMR5, d: R200}\n");
    EXPECT_EQ(row(fbs, "R100").fatek, "R00100");
    EXPECT_EQ(row(fbs, "D10").fatek, "D00010");
    EXPECT_EQ(row(fbs, "Y30").fatek, "Y0030");
    EXPECT_EQ(row(fbs, "M1926").fatek, "M1926");
    EXPECT_EQ(row(fbs, "TMR5").fatek, "RT0005");
    EXPECT_EQ(row(fbs, "sim.time_scale").fatek, "");
    std::ostringstream csv;
    write_tags(csv, fbs.rows, false);
    EXPECT_EQ(csv.str().rfind("name,device,fatek,unit,", 0), 0u) << csv.str().substr(0, 80);

    const TagExport vb = rows_of("profile: vb\ninit: {D100: 1}\n");
    for (const auto& r : vb.rows) EXPECT_EQ(r.fatek, "") << r.name;
    ASSERT_FALSE(vb.rows.empty());
    std::ostringstream vcsv;
    write_tags(vcsv, vb.rows, false);
    EXPECT_EQ(vcsv.str().rfind("name,device,unit,", 0), 0u) << vcsv.str().substr(0, 80);
}

}  // namespace
}  // namespace plcemu::daemon
