// The libmodbus oracle (tests/support/modbus_oracle.hpp; docs/testing.md, "Where the PLC differs
// from libmodbus on purpose"): what it compares, that each deliberate difference is counted
// under its name, and that a difference between the PLC and libmodbus is reported.

#include "support/modbus_oracle.hpp"

#include <gtest/gtest.h>

#include <array>
#include <cstdint>
#include <stdexcept>
#include <string>
#include <vector>

#include "modbus/crc.hpp"
#include "plcemu/image/image.hpp"
#include "plcemu/modbus/dispatcher.hpp"
#include "plcemu/modbus/plc_unit.hpp"
#include "support/profiles.hpp"
#include "modbus/mbap.hpp"
#include "support/wire.hpp"

namespace plcemu::testing {
namespace {

using Bytes = std::vector<std::uint8_t>;
using image::Area;

class Oracle : public ::testing::Test {
protected:
    image::Image img_{testing::fbs_layout()};
    modbus::PlcUnit unit_{img_, testing::fbs().map(), {}};
    std::uint8_t station_ = 1;
    modbus::Dispatcher disp_{modbus::Identity{"FATEK", "FBs-24MC", "9.9.9"}};
    // The PLC on a listener of its own, as the daemon serves it.
    listener::ProtocolSetup setup() {
        return {{{"", &station_, &disp_, &unit_, 0, nullptr}}, listener::UnknownUnit::Refuse, {}};
    }
    modbus_slave::ModbusTcp tcp_{setup()};
    modbus_slave::ModbusRtu rtu_{setup()};
    PlcSide plc_{tcp_, rtu_};
    std::array<std::uint8_t, modbus::kMaxTcpAdu> out_{};

    // Serves `pdu` over TCP to `unit` through the oracle; returns how it went.
    ModbusOracle::Result tcp(const Bytes& pdu, std::uint8_t unit = 1) {
        Bytes adu{0x12, 0x34, 0, 0, 0, static_cast<std::uint8_t>(pdu.size() + 1), unit};
        adu.insert(adu.end(), pdu.begin(), pdu.end());
        return ModbusOracle::get().serve(plc_, unit_, Framing::Tcp, adu, out_);
    }
    // The same as an RTU frame.
    ModbusOracle::Result rtu(const Bytes& pdu, std::uint8_t unit = 1) {
        Bytes f{unit};
        f.insert(f.end(), pdu.begin(), pdu.end());
        const std::uint16_t crc = modbus::crc16(f.data(), f.size());
        f.push_back(static_cast<std::uint8_t>(crc & 0xFF));
        f.push_back(static_cast<std::uint8_t>(crc >> 8));
        return ModbusOracle::get().serve(plc_, unit_, Framing::Rtu, f, out_);
    }
    // Serves `pdu` and expects it counted under `c` without a mismatch.
    void expect_case(const ModbusOracle::Result& r, OracleCase c) {
        EXPECT_EQ(r.how, c) << ModbusOracle::name(r.how);
        EXPECT_EQ(r.mismatch, "");
    }
};

TEST_F(Oracle, ReadsAndWritesAreComparedWithLibmodbus) {
    img_.set_word(Area::R, 10, 0x1234);
    img_.set_bit(Area::Y, 3, true);
    const auto before = ModbusOracle::get().count(OracleCase::Compared);
    expect_case(tcp(read_pdu(0x03, 10, 3)), OracleCase::Compared);
    expect_case(rtu(read_pdu(0x01, 0, 10)), OracleCase::Compared);
    expect_case(tcp(write_registers_pdu(6000, {7, 8, 9})), OracleCase::Compared);
    EXPECT_EQ(img_.word(Area::D, 2), 9);
    expect_case(rtu(write_coils_pdu(0, {true, false, true})), OracleCase::Compared);
    EXPECT_FALSE(img_.bit(Area::Y, 1));
    // A broadcast write: neither answers, both write.
    expect_case(rtu(write_single_pdu(0x06, 6005, 55), 0), OracleCase::Compared);
    EXPECT_EQ(img_.word(Area::D, 5), 55);
    // Quantities libmodbus refuses before looking at an address; a code neither serves.
    expect_case(tcp(read_pdu(0x03, 10, 126)), OracleCase::Compared);
    expect_case(tcp({0x41, 0, 0}), OracleCase::Compared);
    EXPECT_EQ(ModbusOracle::get().count(OracleCase::Compared), before + 7);
}

// The PLC's map decides what an address means: a gap, a read-only item or a write-protected
// range refuses the window, and libmodbus, given no mapping there, must refuse it the same way.
TEST_F(Oracle, WindowsTheMapRefusesAreComparedAsRefusals) {
    expect_case(tcp(read_pdu(0x03, 4500, 1)), OracleCase::ComparedRefused);  // a gap
    expect_case(tcp(write_single_pdu(0x05, 1000, 0xFF00)),
                OracleCase::ComparedRefused);  // X0: read-only
    EXPECT_FALSE(img_.bit(Area::X, 0));
    unit_.set_policy({false, {{Area::D, 100, 100}}});
    expect_case(tcp(write_registers_pdu(6099, {1, 2})), OracleCase::ComparedRefused);
    EXPECT_EQ(img_.word(Area::D, 99), 0);
}

TEST_F(Oracle, DeliberateDifferencesAreCountedByName) {
    expect_case(tcp({0x2B, 0x0E, 0x01, 0x00}), OracleCase::Identity);
    expect_case(tcp({0x11}), OracleCase::Identity);
    expect_case(tcp({0x08, 0, 0, 1, 2}), OracleCase::Identity);
    expect_case(tcp({0x07}), OracleCase::ReadExceptionStatus);
    expect_case(tcp({0x83, 0, 0, 0, 1}), OracleCase::FunctionAbove7F);
    expect_case(tcp({0x03, 0, 0, 0}), OracleCase::LengthNotFramed);
    expect_case(tcp(read_pdu(0x03, 0, 1), 7), OracleCase::NotThePlc);
    expect_case(tcp(write_single_pdu(0x05, 4500, 0x1234)), OracleCase::Fc05ValueFirst);
    Bytes coils = write_coils_pdu(0, {true});
    coils[5] = 2;
    coils.push_back(0);
    expect_case(tcp(coils), OracleCase::Fc0FByteCount);
    expect_case(rtu({0x17, 0, 0, 0, 1, 0x17, 0x70, 0, 1, 2, 0, 9}, 0), OracleCase::BroadcastFc17);
    EXPECT_EQ(img_.word(Area::D, 0), 0);
    Bytes proto{0x12, 0x34, 0, 1, 0, 6, 1, 0x03, 0, 0, 0, 1};
    EXPECT_EQ(ModbusOracle::get().serve(plc_, unit_, Framing::Tcp, proto, out_).how,
              OracleCase::ProtocolId);
    EXPECT_GE(ModbusOracle::get().count(OracleCase::Identity), 3u);
    const std::string s = ModbusOracle::get().summary();
    EXPECT_NE(s.find("oracle: fc05-value-first: "), std::string::npos) << s;
}

// A PLC that answers other than libmodbus is reported: here the oracle reads another image than
// the one the dispatcher serves.
TEST_F(Oracle, ADifferenceIsReported) {
    image::Image other{testing::fbs_layout()};
    modbus::PlcUnit other_unit{other, testing::fbs().map(), {}};
    img_.set_word(Area::R, 0, 1);
    const auto r = ModbusOracle::get().serve(plc_, other_unit, Framing::Tcp,
                                             Bytes{0, 1, 0, 0, 0, 6, 1, 0x03, 0, 0, 0, 1}, out_);
    EXPECT_NE(r.mismatch.find("answer differently"), std::string::npos) << r.mismatch;
    // A write that lands elsewhere than in libmodbus' cell.
    const auto w = ModbusOracle::get().serve(plc_, other_unit, Framing::Tcp,
                                             Bytes{0, 1, 0, 0, 0, 6, 1, 0x06, 0, 0, 0, 5}, out_);
    EXPECT_NE(w.mismatch.find("left address 0"), std::string::npos) << w.mismatch;
}

}  // namespace
}  // namespace plcemu::testing
