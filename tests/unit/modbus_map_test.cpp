// FBs Modbus map and dispatch (FBs manual 13-50/51; docs/profile-fbs.md, Modbus map): every row of
// the manual's table read and written through the dispatcher, the gaps, read-only items, the
// R3968/R3972/R3975 user maps, quantity limits, exceptions 01/02/03, function codes 05/15/16/22/23,
// unit IDs on TCP and RTU.

#include <gtest/gtest.h>

#include <cstdint>
#include <string>
#include <vector>

#include "support/profiles.hpp"
#include "plcemu/image/image.hpp"
#include "plcemu/modbus/address_map.hpp"
#include "plcemu/modbus/dispatcher.hpp"
#include "plcemu/modbus/function_handler.hpp"
#include "plcemu/modbus/plc_unit.hpp"
#include "support/wire.hpp"

namespace plcemu::modbus {
namespace {

using image::Area;
using Bytes = std::vector<std::uint8_t>;
namespace wire = plcemu::testing;

constexpr std::uint8_t kIllegalFunction = 0x01;
constexpr std::uint8_t kIllegalAddress = 0x02;
constexpr std::uint8_t kIllegalValue = 0x03;
constexpr std::uint8_t kGatewayTarget = 0x0B;

std::uint8_t hi(std::uint16_t v) { return static_cast<std::uint8_t>(v >> 8); }
std::uint8_t lo(std::uint16_t v) { return static_cast<std::uint8_t>(v & 0xFF); }

// One row of the FBs manual's table (13-50/51), written down independently of the code's table.
struct ManualRow {
    const char* name;
    Table table;
    std::uint16_t first;  // wire address
    std::uint16_t last;   // wire address
    Area area;
    std::uint32_t first_device;
    bool writable;
};

const std::vector<ManualRow>& manual_rows() {
    static const std::vector<ManualRow> rows{
        {"00001-00256 Y0-Y255", Table::Coils, 0, 255, Area::Y, 0, true},
        {"01001-01256 X0-X255", Table::Coils, 1000, 1255, Area::X, 0, false},
        {"02001-04002 M0-M2001", Table::Coils, 2000, 4001, Area::M, 0, true},
        {"06001-07000 S0-S999", Table::Coils, 6000, 6999, Area::S, 0, true},
        {"09001-09256 T0-T255 status", Table::Coils, 9000, 9255, Area::T, 0, true},
        {"09501-09756 C0-C255 status", Table::Coils, 9500, 9755, Area::C, 0, true},
        {"40001-44168 R0-R4167", Table::HoldingRegisters, 0, 4167, Area::R, 0, true},
        {"45001-45999 R5000-R5998", Table::HoldingRegisters, 5000, 5998, Area::R, 5000, true},
        {"46001-48999 D0-D2998", Table::HoldingRegisters, 6000, 8998, Area::D, 0, true},
        {"49001-49256 T0-T255 value", Table::HoldingRegisters, 9000, 9255, Area::TV, 0, true},
        {"49501-49700 C0-C199 value", Table::HoldingRegisters, 9500, 9699, Area::CV, 0, true},
        {"49701-49812 C200-C255 value", Table::HoldingRegisters, 9700, 9811, Area::CV, 200, true},
    };
    return rows;
}

class ModbusMap : public ::testing::Test {
protected:
    image::Image img_{testing::fbs_layout()};
    PlcUnit unit_{img_, testing::fbs().map(), {}};
    std::uint8_t station_ = 1;
    Dispatcher disp_{Identity{"FATEK", "FBs-24MC", "9.9.9"}};
    wire::Wire wire_{disp_, unit_, station_};

    Bytes tcp(const Bytes& pdu, std::uint8_t unit = 1) { return wire_.tcp(unit, pdu); }
    Bytes rtu(const Bytes& pdu, std::uint8_t unit = 1) { return wire_.rtu(unit, pdu); }

    std::uint8_t read_exception(std::uint8_t fc, std::uint16_t addr, std::uint16_t qty) {
        return wire::exception_of(tcp(wire::read_pdu(fc, addr, qty)));
    }
    std::vector<std::uint16_t> read_words(std::uint8_t fc, std::uint16_t addr, std::uint16_t qty) {
        const Bytes r = tcp(wire::read_pdu(fc, addr, qty));
        EXPECT_EQ(wire::exception_of(r), 0) << "fc " << int(fc) << " addr " << addr;
        return wire::reply_words(r);
    }
    std::vector<bool> read_bits(std::uint8_t fc, std::uint16_t addr, std::uint16_t qty) {
        const Bytes r = tcp(wire::read_pdu(fc, addr, qty));
        EXPECT_EQ(wire::exception_of(r), 0) << "fc " << int(fc) << " addr " << addr;
        return wire::reply_bits(r, qty);
    }
    std::uint8_t write_register(std::uint16_t addr, std::uint16_t v) {
        return wire::exception_of(tcp(wire::write_single_pdu(0x06, addr, v)));
    }
    std::uint8_t write_coil(std::uint16_t addr, bool v) {
        return wire::exception_of(tcp(wire::write_single_pdu(0x05, addr, v ? 0xFF00 : 0x0000)));
    }
    std::uint8_t write_registers(std::uint16_t addr, const std::vector<std::uint16_t>& v) {
        return wire::exception_of(tcp(wire::write_registers_pdu(addr, v)));
    }
    std::uint8_t write_coils(std::uint16_t addr, const std::vector<bool>& v) {
        return wire::exception_of(tcp(wire::write_coils_pdu(addr, v)));
    }

    // Reads element `wire_addr` of a row through Modbus.
    std::uint16_t read_one(const ManualRow& row, std::uint16_t wire_addr) {
        if (row.table == Table::Coils) {
            const auto b = read_bits(0x01, wire_addr, 1);
            return b.size() == 1 && b[0] ? 1 : 0;
        }
        const auto w = read_words(0x03, wire_addr, 1);
        return w.size() == 1 ? w[0] : 0xDEAD;
    }
    std::uint16_t device(const ManualRow& row, std::uint16_t wire_addr) const {
        const std::uint32_t i = row.first_device + (wire_addr - row.first);
        return image::is_bit_area(row.area) ? img_.bit(row.area, i) : img_.word(row.area, i);
    }
    void set_device(const ManualRow& row, std::uint16_t wire_addr, std::uint16_t v) {
        const std::uint32_t i = row.first_device + (wire_addr - row.first);
        if (image::is_bit_area(row.area)) {
            img_.set_bit(row.area, i, v != 0);
        } else {
            img_.set_word(row.area, i, v);
        }
    }
};

// FBs manual 13-50/51: every row reads its device range, at its first, a middle and its last
// address.
TEST_F(ModbusMap, EveryRowReadsItsDevices) {
    for (const auto& row : manual_rows()) {
        SCOPED_TRACE(row.name);
        const std::uint16_t mid = static_cast<std::uint16_t>((row.first + row.last) / 2);
        for (std::uint16_t a : {row.first, mid, row.last}) {
            const bool bit = row.table == Table::Coils;
            const std::uint16_t v = bit ? 1 : static_cast<std::uint16_t>(0x1000 + a);
            set_device(row, a, v);
            EXPECT_EQ(read_one(row, a), v) << "wire " << a;
            set_device(row, a, 0);
            EXPECT_EQ(read_one(row, a), 0) << "wire " << a;
        }
        // The whole row in maximal chunks: element k is device first_device + k.
        const std::uint16_t chunk = row.table == Table::Coils ? 2000 : 125;
        for (std::uint32_t a = row.first; a <= row.last; a += chunk) {
            const auto n =
                static_cast<std::uint16_t>(std::min<std::uint32_t>(chunk, row.last + 1u - a));
            for (std::uint16_t k = 0; k < n; ++k) {
                const auto w = static_cast<std::uint16_t>(a + k);
                set_device(row, w, row.table == Table::Coils ? (w % 3 == 0) : w);
            }
            if (row.table == Table::Coils) {
                const auto bits = read_bits(0x01, static_cast<std::uint16_t>(a), n);
                ASSERT_EQ(bits.size(), n);
                for (std::uint16_t k = 0; k < n; ++k) EXPECT_EQ(bits[k], (a + k) % 3 == 0);
            } else {
                const auto words = read_words(0x03, static_cast<std::uint16_t>(a), n);
                ASSERT_EQ(words.size(), n);
                for (std::uint16_t k = 0; k < n; ++k) EXPECT_EQ(words[k], a + k);
            }
        }
    }
}

// FBs manual 13-50/51: every writable row is written by FC05/06 and FC15/16 at its first and last
// address; X (01 only) refuses writes with exception 02 and stays unchanged.
TEST_F(ModbusMap, EveryRowWritesItsDevicesOrRefuses) {
    for (const auto& row : manual_rows()) {
        SCOPED_TRACE(row.name);
        const bool bit = row.table == Table::Coils;
        for (std::uint16_t a : {row.first, row.last}) {
            set_device(row, a, 0);
            const std::uint8_t e1 = bit ? write_coil(a, true) : write_register(a, 0xBEEF);
            const std::uint16_t want1 = bit ? 1 : 0xBEEF;
            if (row.writable) {
                EXPECT_EQ(e1, 0) << "single write at " << a;
                EXPECT_EQ(device(row, a), want1) << "single write at " << a;
            } else {
                EXPECT_EQ(e1, kIllegalAddress) << "single write at " << a;
                EXPECT_EQ(device(row, a), 0) << "single write at " << a;
            }
            set_device(row, a, 0);
            const std::uint8_t e2 = bit ? write_coils(a, {true}) : write_registers(a, {0x1234});
            const std::uint16_t want2 = bit ? 1 : 0x1234;
            if (row.writable) {
                EXPECT_EQ(e2, 0) << "multiple write at " << a;
                EXPECT_EQ(device(row, a), want2) << "multiple write at " << a;
            } else {
                EXPECT_EQ(e2, kIllegalAddress) << "multiple write at " << a;
                EXPECT_EQ(device(row, a), 0) << "multiple write at " << a;
            }
        }
        // Clearing again through Modbus.
        if (row.writable) {
            set_device(row, row.last, 1);
            EXPECT_EQ(bit ? write_coil(row.last, false) : write_register(row.last, 0), 0);
            EXPECT_EQ(device(row, row.last), 0);
        }
    }
}

// docs/profile-fbs.md, Modbus map: a request that runs past the last address of a row into a gap is
// refused whole.
TEST_F(ModbusMap, RequestsRunningIntoAGapAreRefusedWhole) {
    for (const auto& row : manual_rows()) {
        SCOPED_TRACE(row.name);
        const bool bit = row.table == Table::Coils;
        const std::uint8_t fc = bit ? 0x01 : 0x03;
        // The two last elements are fine.
        EXPECT_EQ(read_exception(fc, static_cast<std::uint16_t>(row.last - 1), 2), 0);
        if (row.last == 9699) continue;  // C199 value continues with C200 (next test)
        EXPECT_EQ(read_exception(fc, row.last, 2), kIllegalAddress);
        if (row.writable) {
            set_device(row, row.last, 0);
            const std::uint8_t e =
                bit ? write_coils(row.last, {true, true}) : write_registers(row.last, {7, 7});
            EXPECT_EQ(e, kIllegalAddress);
            EXPECT_EQ(device(row, row.last), 0) << "nothing of a refused write lands";
        }
    }
}

// The rows 49501-49700 (C0-C199) and 49701-49812 (C200-C255) are one run of counter values.
TEST_F(ModbusMap, CounterValueRowsAreContiguous) {
    img_.set_word(Area::CV, 199, 11);
    img_.set_word(Area::CV, 200, 22);
    img_.set_word(Area::CV, 201, 33);
    EXPECT_EQ(read_words(0x03, 9699, 3), (std::vector<std::uint16_t>{11, 22, 33}));
    EXPECT_EQ(write_registers(9699, {1, 2, 3}), 0);
    EXPECT_EQ(img_.word(Area::CV, 199), 1);
    EXPECT_EQ(img_.word(Area::CV, 201), 3);
}

// docs/profile-fbs.md, Modbus map: the gaps of the table (and R4168-R4999, R5999-R8071,
// D2999-D3999) get exception 02.
TEST_F(ModbusMap, GapsAreIllegalDataAddress) {
    for (std::uint16_t a :
         std::vector<std::uint16_t>{256, 500, 999, 1256, 1999, 4002, 5999, 7000, 8999, 9256, 9499,
                                    9756, 9999, 10000, 30000, 65535}) {
        EXPECT_EQ(read_exception(0x01, a, 1), kIllegalAddress) << "coil " << a;
        EXPECT_EQ(write_coil(a, true), kIllegalAddress) << "coil " << a;
        EXPECT_EQ(write_coils(a, {true}), kIllegalAddress) << "coil " << a;
    }
    for (std::uint16_t a : std::vector<std::uint16_t>{4168, 4500, 4999, 5999, 8999, 9256, 9499,
                                                      9812, 9999, 10000, 40000, 65535}) {
        EXPECT_EQ(read_exception(0x03, a, 1), kIllegalAddress) << "register " << a;
        EXPECT_EQ(write_register(a, 1), kIllegalAddress) << "register " << a;
        EXPECT_EQ(write_registers(a, {1}), kIllegalAddress) << "register " << a;
    }
    // Wire 65535 with a quantity of 2 would wrap around to 0: still 02, not Y0.
    EXPECT_EQ(read_exception(0x01, 65535, 2), kIllegalAddress);
    EXPECT_EQ(read_exception(0x03, 65535, 2), kIllegalAddress);
    // A read that starts in a row and ends in a gap, from the middle of a gap into a row.
    EXPECT_EQ(read_exception(0x03, 4100, 100), kIllegalAddress);
    EXPECT_EQ(read_exception(0x03, 4990, 20), kIllegalAddress);
    EXPECT_EQ(read_exception(0x01, 1990, 20), kIllegalAddress);
    // The unmapped R and D devices are never reached.
    img_.set_word(Area::R, 4168, 9);
    img_.set_word(Area::R, 5999, 9);
    img_.set_word(Area::D, 2999, 9);
    EXPECT_EQ(read_exception(0x03, 5999, 1), kIllegalAddress);
    EXPECT_EQ(read_exception(0x03, 8999, 1), kIllegalAddress);
}

// docs/profile-fbs.md, Modbus map: writes to read-only items (X, IR R3840-R3903, M1920-M1927,
// R4136-R4138) get exception 02 and change nothing, whatever the function code; reads work.
TEST_F(ModbusMap, ReadOnlyItemsRefuseWritesAndStayUnchanged) {
    struct Item {
        Table table;
        std::uint16_t wire;
        Area area;
        std::uint32_t index;
    };
    const std::vector<Item> items{
        {Table::Coils, 1000, Area::X, 0},
        {Table::Coils, 1255, Area::X, 255},
        {Table::HoldingRegisters, 3840, Area::R, 3840},
        {Table::HoldingRegisters, 3903, Area::R, 3903},
        {Table::Coils, 3920, Area::M, 1920},
        {Table::Coils, 3927, Area::M, 1927},
        {Table::HoldingRegisters, 4136, Area::R, 4136},
        {Table::HoldingRegisters, 4138, Area::R, 4138},
    };
    for (const auto& it : items) {
        SCOPED_TRACE(std::string(image::area_name(it.area)) + std::to_string(it.index));
        if (it.table == Table::Coils) {
            img_.set_bit(it.area, it.index, false);
            EXPECT_EQ(write_coil(it.wire, true), kIllegalAddress);
            EXPECT_EQ(write_coils(it.wire, {true}), kIllegalAddress);
            EXPECT_FALSE(img_.bit(it.area, it.index));
            img_.set_bit(it.area, it.index, true);
            EXPECT_EQ(read_bits(0x01, it.wire, 1), std::vector<bool>{true});
        } else {
            img_.set_word(it.area, it.index, 77);
            EXPECT_EQ(write_register(it.wire, 1), kIllegalAddress);
            EXPECT_EQ(write_registers(it.wire, {1}), kIllegalAddress);
            const Bytes mask{0x16, hi(it.wire), lo(it.wire), 0x00, 0x00, 0xFF, 0xFF};
            EXPECT_EQ(wire::exception_of(tcp(mask)), kIllegalAddress);
            const Bytes rw{0x17,        0x00, 0x00, 0x00, 0x01, hi(it.wire),
                           lo(it.wire), 0x00, 0x01, 0x02, 0x00, 0x01};
            EXPECT_EQ(wire::exception_of(tcp(rw)), kIllegalAddress);
            EXPECT_EQ(img_.word(it.area, it.index), 77);
            EXPECT_EQ(read_words(0x03, it.wire, 1), std::vector<std::uint16_t>{77});
        }
    }
    // A multiple write that only touches a read-only item at one end is refused whole.
    img_.set_word(Area::R, 3839, 0);
    EXPECT_EQ(write_registers(3838, {5, 5, 5}), kIllegalAddress);
    EXPECT_EQ(img_.word(Area::R, 3838), 0);
    EXPECT_EQ(img_.word(Area::R, 3839), 0);
    img_.set_bit(Area::M, 1919, false);
    EXPECT_EQ(write_coils(3919, {true, true}), kIllegalAddress);
    EXPECT_FALSE(img_.bit(Area::M, 1919));
    // Neighbours of the read-only items are writable.
    EXPECT_EQ(write_register(3839, 1), 0);
    EXPECT_EQ(write_register(3904, 1), 0);  // OR0
    EXPECT_EQ(write_register(4135, 1), 0);
    EXPECT_EQ(write_register(4139, 1), 0);
    EXPECT_EQ(write_coil(3919, true), 0);
    EXPECT_EQ(write_coil(3928, true), 0);
}

// FBs manual 13-50/51: R3968 = A55Ah replaces the coil map by R3969-R3971 and the holding-register
// map by R3978-R3980; any other value restores the manual's table.
TEST_F(ModbusMap, R3968RemapReplacesCoilAndHoldingMaps) {
    img_.set_word(Area::R, 3969, 100);   // coils 100..
    img_.set_word(Area::R, 3970, 500);   // -> M500..
    img_.set_word(Area::R, 3971, 10);    // 10 of them
    img_.set_word(Area::R, 3978, 20);    // registers 20..
    img_.set_word(Area::R, 3979, 5000);  // -> R5000..
    img_.set_word(Area::R, 3980, 8);     // 8 of them
    img_.set_word(Area::R, 5000, 0xAAAA);
    img_.set_word(Area::R, 5007, 0xBBBB);
    img_.set_bit(Area::M, 500, true);

    // Not yet active: the default table.
    EXPECT_EQ(read_words(0x03, 20, 1), std::vector<std::uint16_t>{0});  // R20
    EXPECT_EQ(read_bits(0x01, 100, 1), std::vector<bool>{false});       // Y100
    img_.set_word(Area::R, 3968, 0xA55A);

    EXPECT_EQ(read_words(0x03, 20, 1), std::vector<std::uint16_t>{0xAAAA});
    EXPECT_EQ(read_words(0x03, 20, 8).back(), 0xBBBB);
    EXPECT_EQ(read_exception(0x03, 19, 1), kIllegalAddress);
    EXPECT_EQ(read_exception(0x03, 27, 2), kIllegalAddress);
    EXPECT_EQ(read_exception(0x03, 6000, 1), kIllegalAddress);  // D0 is not in the remap
    EXPECT_EQ(write_register(27, 0x4242), 0);
    EXPECT_EQ(img_.word(Area::R, 5007), 0x4242);
    EXPECT_EQ(write_registers(20, {1, 2}), 0);
    EXPECT_EQ(img_.word(Area::R, 5001), 2);

    EXPECT_EQ(read_bits(0x01, 100, 1), std::vector<bool>{true});  // M500
    EXPECT_EQ(read_exception(0x01, 99, 1), kIllegalAddress);
    EXPECT_EQ(read_exception(0x01, 109, 2), kIllegalAddress);
    EXPECT_EQ(read_exception(0x01, 0, 1), kIllegalAddress);  // Y0 is not in the remap
    EXPECT_EQ(write_coil(109, true), 0);
    EXPECT_TRUE(img_.bit(Area::M, 509));
    EXPECT_EQ(write_coils(100, {false, true}), 0);
    EXPECT_FALSE(img_.bit(Area::M, 500));
    EXPECT_TRUE(img_.bit(Area::M, 501));

    // Read-only items stay read-only through the remap.
    img_.set_word(Area::R, 3979, 4130);                 // registers 20.. -> R4130..R4137
    EXPECT_EQ(write_register(26, 1), kIllegalAddress);  // R4136
    EXPECT_EQ(write_register(25, 1), 0);                // R4135
    // A remap beyond the area, or into R4168-R4999, is 02.
    img_.set_word(Area::R, 3979, 8070);
    EXPECT_EQ(read_exception(0x03, 20, 2), 0);
    EXPECT_EQ(read_exception(0x03, 20, 3), kIllegalAddress);
    img_.set_word(Area::R, 3979, 4165);
    EXPECT_EQ(read_exception(0x03, 20, 3), 0);
    EXPECT_EQ(read_exception(0x03, 20, 4), kIllegalAddress);
    img_.set_word(Area::R, 3970, 1995);  // coils 100.. -> M1995..M2004: beyond M2001
    EXPECT_EQ(read_exception(0x01, 100, 7), 0);
    EXPECT_EQ(read_exception(0x01, 100, 8), kIllegalAddress);

    // Any other value of R3968: the manual's table again.
    img_.set_word(Area::R, 3968, 0xA55B);
    img_.set_word(Area::R, 20, 0x2020);
    EXPECT_EQ(read_words(0x03, 20, 1), std::vector<std::uint16_t>{0x2020});
    EXPECT_EQ(read_exception(0x03, 6000, 1), 0);
    EXPECT_EQ(read_exception(0x01, 0, 1), 0);
}

// FBs manual 13-50/51: with R3968 = A55Ah and a count of 0, no coil / holding register is mapped.
TEST_F(ModbusMap, R3968RemapWithCountZeroMapsNothing) {
    img_.set_word(Area::R, 3968, 0xA55A);
    EXPECT_EQ(read_exception(0x01, 0, 1), kIllegalAddress);
    EXPECT_EQ(read_exception(0x03, 0, 1), kIllegalAddress);
    EXPECT_EQ(write_register(3968, 0), kIllegalAddress);
}

// FBs manual 13-50/51: FC02 through R3972-R3974 and FC04 through R3975-R3977, independent of R3968;
// a count of 0 (the default) means the function code is not served: exception 01.
TEST_F(ModbusMap, DiscreteInputAndInputRegisterMaps) {
    EXPECT_EQ(read_exception(0x02, 0, 1), kIllegalFunction);
    EXPECT_EQ(read_exception(0x04, 0, 1), kIllegalFunction);

    img_.set_word(Area::R, 3972, 10);    // discrete inputs 10..
    img_.set_word(Area::R, 3973, 1920);  // -> M1920..
    img_.set_word(Area::R, 3974, 8);
    img_.set_word(Area::R, 3975, 300);   // input registers 300..
    img_.set_word(Area::R, 3976, 4128);  // -> R4128.. (calendar)
    img_.set_word(Area::R, 3977, 11);
    img_.set_bit(Area::M, 1926, true);
    img_.set_word(Area::R, 4128, 59);
    img_.set_word(Area::R, 4138, 10);

    const auto bits = read_bits(0x02, 10, 8);
    ASSERT_EQ(bits.size(), 8u);
    EXPECT_TRUE(bits[6]);  // M1926
    EXPECT_FALSE(bits[5]);
    EXPECT_EQ(read_exception(0x02, 9, 1), kIllegalAddress);
    EXPECT_EQ(read_exception(0x02, 17, 2), kIllegalAddress);
    const auto words = read_words(0x04, 300, 11);
    ASSERT_EQ(words.size(), 11u);
    EXPECT_EQ(words[0], 59);
    EXPECT_EQ(words[10], 10);
    EXPECT_EQ(read_exception(0x04, 311, 1), kIllegalAddress);
    EXPECT_EQ(read_exception(0x04, 299, 1), kIllegalAddress);

    // Independent of R3968 (and the coil/holding maps stay as they are).
    img_.set_word(Area::R, 3968, 0xA55A);
    EXPECT_EQ(read_words(0x04, 300, 1), std::vector<std::uint16_t>{59});
    img_.set_word(Area::R, 3968, 0);

    // Into R4168-R4999 or beyond R8071: 02.
    img_.set_word(Area::R, 3976, 4160);
    EXPECT_EQ(read_exception(0x04, 300, 8), 0);
    EXPECT_EQ(read_exception(0x04, 300, 9), kIllegalAddress);
    img_.set_word(Area::R, 3976, 8071);
    EXPECT_EQ(read_exception(0x04, 300, 1), 0);
    EXPECT_EQ(read_exception(0x04, 300, 2), kIllegalAddress);

    // Back to a count of 0: 01 again.
    img_.set_word(Area::R, 3974, 0);
    img_.set_word(Area::R, 3977, 0);
    EXPECT_EQ(read_exception(0x02, 10, 1), kIllegalFunction);
    EXPECT_EQ(read_exception(0x04, 300, 1), kIllegalFunction);
}

// docs/profile-fbs.md, Modbus map: 32-bit counters C200-C255 take two registers each, low word
// first.
TEST_F(ModbusMap, ThirtyTwoBitCountersAreLowWordFirst) {
    EXPECT_EQ(write_registers(9700, {0x5678, 0x1234}), 0);  // C200 = 12345678h
    EXPECT_EQ(img_.word(Area::CV, 200), 0x5678);
    EXPECT_EQ(img_.word(Area::CV, 201), 0x1234);
    img_.set_word(Area::CV, 310, 0xCDEF);  // C255 low
    img_.set_word(Area::CV, 311, 0x89AB);  // C255 high
    EXPECT_EQ(read_words(0x03, 9810, 2), (std::vector<std::uint16_t>{0xCDEF, 0x89AB}));
}

// docs/profile-fbs.md, Modbus map, quantities: FC01/02 1-2000, FC03/04 1-125, FC15 1-1968,
// FC16 1-123, FC23 read 1-125 / write 1-121, byte counts consistent; else exception 03.
TEST_F(ModbusMap, QuantityLimitsGiveIllegalDataValue) {
    img_.set_word(Area::R, 3972, 0);
    img_.set_word(Area::R, 3973, 0);
    img_.set_word(Area::R, 3974, 2002);
    img_.set_word(Area::R, 3975, 0);
    img_.set_word(Area::R, 3976, 0);
    img_.set_word(Area::R, 3977, 4000);

    for (std::uint8_t fc : {std::uint8_t{0x01}, std::uint8_t{0x02}}) {
        SCOPED_TRACE(int(fc));
        const std::uint16_t start = fc == 0x01 ? 2000 : 0;
        EXPECT_EQ(read_exception(fc, start, 0), kIllegalValue);
        EXPECT_EQ(read_exception(fc, start, 1), 0);
        EXPECT_EQ(read_exception(fc, start, 2000), 0);
        EXPECT_EQ(read_exception(fc, start, 2001), kIllegalValue);
        EXPECT_EQ(read_exception(fc, start, 0xFFFF), kIllegalValue);
    }
    for (std::uint8_t fc : {std::uint8_t{0x03}, std::uint8_t{0x04}}) {
        SCOPED_TRACE(int(fc));
        EXPECT_EQ(read_exception(fc, 0, 0), kIllegalValue);
        EXPECT_EQ(read_exception(fc, 0, 125), 0);
        EXPECT_EQ(read_exception(fc, 0, 126), kIllegalValue);
    }
    // 03 is checked before the address: a bad quantity in a gap is still 03.
    EXPECT_EQ(read_exception(0x03, 4500, 200), kIllegalValue);
    EXPECT_EQ(read_exception(0x01, 500, 0), kIllegalValue);

    // FC15: 1-1968 coils, byte count = ceil(qty / 8).
    // No 1968 writable coils in a row (M1920-M1927 are read-only): the quantity passes and the
    // address check refuses it.
    EXPECT_EQ(write_coils(2000, std::vector<bool>(1968, true)), kIllegalAddress);
    EXPECT_FALSE(img_.bit(Area::M, 0));
    EXPECT_EQ(write_coils(2000, std::vector<bool>(1920, true)), 0);
    EXPECT_TRUE(img_.bit(Area::M, 1919));
    EXPECT_EQ(write_coils(2000, std::vector<bool>(1969, true)), kIllegalValue);
    EXPECT_EQ(write_coils(2000, {}), kIllegalValue);
    {
        Bytes p = wire::write_coils_pdu(2000, std::vector<bool>(9, true));  // 2 bytes
        p[5] = 1;
        p.pop_back();
        EXPECT_EQ(wire::exception_of(tcp(p)), kIllegalValue);  // byte count too small
        Bytes q = wire::write_coils_pdu(2000, std::vector<bool>(8, true));
        q[5] = 2;
        q.push_back(0xFF);
        EXPECT_EQ(wire::exception_of(tcp(q)), kIllegalValue);  // byte count too large
        Bytes r = wire::write_coils_pdu(2000, std::vector<bool>(8, true));
        r.push_back(0xFF);
        EXPECT_EQ(wire::exception_of(tcp(r)), kIllegalValue);  // PDU longer than its byte count
    }
    // FC16: 1-123 registers, byte count = 2 * qty.
    EXPECT_EQ(write_registers(6000, std::vector<std::uint16_t>(123, 9)), 0);
    EXPECT_EQ(img_.word(Area::D, 122), 9);
    EXPECT_EQ(write_registers(6000, std::vector<std::uint16_t>(124, 9)), kIllegalValue);
    EXPECT_EQ(write_registers(6000, {}), kIllegalValue);
    {
        Bytes p = wire::write_registers_pdu(6000, {1, 2});
        p[5] = 3;
        p.pop_back();
        EXPECT_EQ(wire::exception_of(tcp(p)), kIllegalValue);
        Bytes q = wire::write_registers_pdu(6000, {1, 2});
        q.pop_back();  // byte count says 4, 3 follow
        EXPECT_EQ(wire::exception_of(tcp(q)), kIllegalValue);
    }
    img_.set_word(Area::D, 0, 0);
    // FC05: value 0000h or FF00h only.
    EXPECT_EQ(wire::exception_of(tcp(wire::write_single_pdu(0x05, 2000, 0x0001))), kIllegalValue);
    EXPECT_EQ(wire::exception_of(tcp(wire::write_single_pdu(0x05, 2000, 0x00FF))), kIllegalValue);
    EXPECT_EQ(wire::exception_of(tcp(wire::write_single_pdu(0x05, 2000, 0xFFFF))), kIllegalValue);
    // Malformed lengths of the fixed-size requests.
    EXPECT_EQ(wire::exception_of(tcp({0x03, 0x00, 0x00, 0x00})), kIllegalValue);
    EXPECT_EQ(wire::exception_of(tcp({0x06, 0x00, 0x00, 0x00, 0x01, 0x00})), kIllegalValue);
    EXPECT_EQ(wire::exception_of(tcp({0x16, 0x00, 0x00, 0xFF, 0xFF, 0x00})), kIllegalValue);
    EXPECT_EQ(wire::exception_of(tcp({0x10, 0x00, 0x00, 0x00})), kIllegalValue);
    EXPECT_EQ(wire::exception_of(tcp({0x0F, 0x07, 0xD0})), kIllegalValue);
}

Bytes rw_pdu(std::uint16_t raddr,
             std::uint16_t rqty,
             std::uint16_t waddr,
             const std::vector<std::uint16_t>& values) {
    Bytes p{0x17,
            hi(raddr),
            lo(raddr),
            hi(rqty),
            lo(rqty),
            hi(waddr),
            lo(waddr),
            hi(static_cast<std::uint16_t>(values.size())),
            lo(static_cast<std::uint16_t>(values.size())),
            static_cast<std::uint8_t>(values.size() * 2)};
    for (auto v : values) {
        p.push_back(hi(v));
        p.push_back(lo(v));
    }
    return p;
}

// docs/profile-fbs.md, Modbus map, quantities for FC23: read 1-125, write 1-121, byte count =
// 2 * write quantity.
TEST_F(ModbusMap, Fc23QuantityLimits) {
    EXPECT_EQ(wire::exception_of(tcp(rw_pdu(0, 125, 6000, std::vector<std::uint16_t>(121, 1)))), 0);
    EXPECT_EQ(wire::exception_of(tcp(rw_pdu(0, 126, 6000, {1}))), kIllegalValue);
    EXPECT_EQ(wire::exception_of(tcp(rw_pdu(0, 0, 6000, {1}))), kIllegalValue);
    EXPECT_EQ(wire::exception_of(tcp(rw_pdu(0, 1, 6000, std::vector<std::uint16_t>(122, 1)))),
              kIllegalValue);
    EXPECT_EQ(wire::exception_of(tcp(rw_pdu(0, 1, 6000, {}))), kIllegalValue);
    Bytes p = rw_pdu(0, 1, 6000, {1, 2});
    p[9] = 2;  // byte count says one register, two follow
    EXPECT_EQ(wire::exception_of(tcp(p)), kIllegalValue);
    p = rw_pdu(0, 1, 6000, {1, 2});
    p.pop_back();
    EXPECT_EQ(wire::exception_of(tcp(p)), kIllegalValue);
    EXPECT_EQ(wire::exception_of(tcp({0x17, 0, 0, 0, 1})), kIllegalValue);
    // Quantity errors win over address errors.
    EXPECT_EQ(wire::exception_of(tcp(rw_pdu(4500, 126, 4500, {1}))), kIllegalValue);
}

// FC05 writes ON with FF00h and OFF with 0000h and echoes the request.
TEST_F(ModbusMap, Fc05WritesOnAndOff) {
    const Bytes on = wire::write_single_pdu(0x05, 2100, 0xFF00);
    EXPECT_EQ(tcp(on), on);
    EXPECT_TRUE(img_.bit(Area::M, 100));
    const Bytes off = wire::write_single_pdu(0x05, 2100, 0x0000);
    EXPECT_EQ(tcp(off), off);
    EXPECT_FALSE(img_.bit(Area::M, 100));
}

// FC06 echoes the request; FC15/16 answer address and quantity.
TEST_F(ModbusMap, WriteRepliesFollowTheProtocol) {
    const Bytes w = wire::write_single_pdu(0x06, 6001, 0xA5A5);
    EXPECT_EQ(tcp(w), w);
    EXPECT_EQ(img_.word(Area::D, 1), 0xA5A5);
    EXPECT_EQ(tcp(wire::write_registers_pdu(6002, {1, 2, 3})),
              (Bytes{0x10, hi(6002), lo(6002), 0x00, 0x03}));
    EXPECT_EQ(tcp(wire::write_coils_pdu(6000, std::vector<bool>(10, true))),
              (Bytes{0x0F, hi(6000), lo(6000), 0x00, 0x0A}));
    EXPECT_TRUE(img_.bit(Area::S, 9));
    EXPECT_FALSE(img_.bit(Area::S, 10));
}

// FC22 mask write: result = (current AND and_mask) OR (or_mask AND NOT and_mask).
TEST_F(ModbusMap, Fc22MaskWrite) {
    img_.set_word(Area::D, 4, 0x0012);
    const Bytes req{0x16, hi(6004), lo(6004), 0x00, 0xF2, 0x00, 0x25};
    EXPECT_EQ(tcp(req), req);
    EXPECT_EQ(img_.word(Area::D, 4), 0x0017);  // the example of the Modbus specification
    img_.set_word(Area::R, 100, 0xFFFF);
    EXPECT_EQ(wire::exception_of(tcp({0x16, 0x00, 100, 0xFF, 0x00, 0x00, 0x00})), 0);
    EXPECT_EQ(img_.word(Area::R, 100), 0xFF00);
    EXPECT_EQ(wire::exception_of(tcp({0x16, hi(4500), lo(4500), 0, 0, 0, 0})), kIllegalAddress);
}

// FC23: the write is done before the read, and the two may address different areas.
TEST_F(ModbusMap, Fc23ReadWriteMultiple) {
    img_.set_word(Area::R, 0, 0x1111);
    img_.set_word(Area::R, 1, 0x2222);
    Bytes r = tcp(rw_pdu(0, 2, 6000, {0xAAAA, 0xBBBB, 0xCCCC}));  // read R0-R1, write D0-D2
    ASSERT_EQ(wire::exception_of(r), 0);
    EXPECT_EQ(r[0], 0x17);
    EXPECT_EQ(r[1], 4);
    EXPECT_EQ(wire::reply_words(r), (std::vector<std::uint16_t>{0x1111, 0x2222}));
    EXPECT_EQ(img_.word(Area::D, 0), 0xAAAA);
    EXPECT_EQ(img_.word(Area::D, 2), 0xCCCC);
    // Overlapping: the read sees what was just written.
    r = tcp(rw_pdu(6001, 3, 6002, {0x0101}));
    EXPECT_EQ(wire::reply_words(r), (std::vector<std::uint16_t>{0xBBBB, 0x0101, 0}));
    // Read from timers, write into C200 (32-bit).
    img_.set_word(Area::TV, 5, 500);
    r = tcp(rw_pdu(9005, 1, 9700, {0x0002, 0x0001}));
    EXPECT_EQ(wire::reply_words(r), std::vector<std::uint16_t>{500});
    EXPECT_EQ(img_.word(Area::CV, 201), 1);
    // Either half unmapped: 02, and the write does not land.
    img_.set_word(Area::D, 10, 0);
    EXPECT_EQ(wire::exception_of(tcp(rw_pdu(4500, 1, 6010, {9}))), kIllegalAddress);
    EXPECT_EQ(img_.word(Area::D, 10), 0);
    EXPECT_EQ(wire::exception_of(tcp(rw_pdu(6010, 1, 4500, {9}))), kIllegalAddress);
}

// docs/profile-fbs.md, Modbus map: function codes the emulator does not implement get exception 01.
TEST_F(ModbusMap, UnknownFunctionCodesAreIllegalFunction) {
    for (std::uint8_t fc : std::vector<std::uint8_t>{0x00, 0x07, 0x09, 0x0B, 0x0C, 0x14, 0x15, 0x18,
                                                     0x2A, 0x41, 0x64, 0x7F}) {
        EXPECT_EQ(wire::exception_of(tcp({fc, 0x00, 0x00, 0x00, 0x01})), kIllegalFunction)
            << "fc " << int(fc);
    }
    // FC08 with a subfunction other than 00, FC2Bh with a MEI type other than 0Eh.
    EXPECT_EQ(wire::exception_of(tcp({0x08, 0x00, 0x01, 0x00, 0x00})), kIllegalFunction);
    EXPECT_EQ(wire::exception_of(tcp({0x2B, 0x0D, 0x01, 0x00})), kIllegalFunction);
}

// docs/profile-fbs.md, Modbus map: FC08/00 echoes, FC11h reports the slave, FC2Bh/0Eh gives FATEK,
// the model and the version.
TEST_F(ModbusMap, DiagnosticsReportAndIdentification) {
    const Bytes echo{0x08, 0x00, 0x00, 0x12, 0x34};
    EXPECT_EQ(tcp(echo), echo);

    const Bytes id = tcp({0x11});
    ASSERT_GE(id.size(), 4u);
    EXPECT_EQ(id[0], 0x11);
    EXPECT_EQ(id[1], id.size() - 2);
    EXPECT_EQ(id[3], 0xFF);  // run indicator
    const std::string text(id.begin() + 4, id.end());
    EXPECT_NE(text.find("FBs-24MC"), std::string::npos) << text;

    const Bytes dev = tcp({0x2B, 0x0E, 0x01, 0x00});
    ASSERT_GE(dev.size(), 7u);
    EXPECT_EQ(dev[0], 0x2B);
    EXPECT_EQ(dev[6], 3);  // basic: vendor, product code, revision
    std::vector<std::string> objects;
    for (std::size_t k = 7; k + 2 <= dev.size();) {
        const std::size_t len = dev[k + 1];
        objects.emplace_back(dev.begin() + static_cast<long>(k + 2),
                             dev.begin() + static_cast<long>(k + 2 + len));
        k += 2 + len;
    }
    EXPECT_EQ(objects, (std::vector<std::string>{"FATEK", "FBs-24MC", "9.9.9"}));
    // Malformed lengths: 03.
    EXPECT_EQ(wire::exception_of(tcp({0x08, 0x00})), kIllegalValue);
    EXPECT_EQ(wire::exception_of(tcp({0x11, 0x00})), kIllegalValue);
    EXPECT_EQ(wire::exception_of(tcp({0x2B, 0x0E, 0x01})), kIllegalValue);
    EXPECT_EQ(wire::exception_of(tcp({0x2B, 0x0E, 0x05, 0x00})), kIllegalValue);  // read code 5
    // Individual access to an object that does not exist: 02.
    EXPECT_EQ(wire::exception_of(tcp({0x2B, 0x0E, 0x04, 0x42})), kIllegalAddress);
}

// docs/profile-fbs.md, Modbus map (TCP): the station and 255 are answered, any other unit gets 0Bh
// (or, when configured, no answer at all).
TEST_F(ModbusMap, TcpUnitIds) {
    img_.set_word(Area::R, 7, 77);
    EXPECT_EQ(wire::reply_words(tcp(wire::read_pdu(0x03, 7, 1), 1)),
              std::vector<std::uint16_t>{77});
    EXPECT_EQ(wire::reply_words(tcp(wire::read_pdu(0x03, 7, 1), 255)),
              std::vector<std::uint16_t>{77});
    // Modbus TCP implementation guide §4.4.1.2: unit 0 addresses the device itself over TCP.
    EXPECT_EQ(wire::reply_words(tcp(wire::read_pdu(0x03, 7, 1), 0)),
              std::vector<std::uint16_t>{77});
    for (std::uint8_t u : std::vector<std::uint8_t>{2, 17, 247, 254}) {
        EXPECT_EQ(wire::exception_of(tcp(wire::read_pdu(0x03, 7, 1), u)), kGatewayTarget)
            << "unit " << int(u);
        // A write to another unit does not land.
        EXPECT_EQ(wire::exception_of(tcp(wire::write_single_pdu(0x06, 7, 1), u)), kGatewayTarget);
        EXPECT_EQ(img_.word(Area::R, 7), 77);
    }
    // The station is read on every request (R4055 may change it).
    station_ = 17;
    EXPECT_EQ(wire::reply_words(tcp(wire::read_pdu(0x03, 7, 1), 17)),
              std::vector<std::uint16_t>{77});
    EXPECT_EQ(wire::exception_of(tcp(wire::read_pdu(0x03, 7, 1), 1)), kGatewayTarget);
    EXPECT_EQ(wire::reply_words(tcp(wire::read_pdu(0x03, 7, 1), 255)),
              std::vector<std::uint16_t>{77});
    // "Stay silent" policy.
    wire_.set_unknown_unit(listener::UnknownUnit::Silent);
    EXPECT_TRUE(tcp(wire::read_pdu(0x03, 7, 1), 1).empty());
    EXPECT_FALSE(tcp(wire::read_pdu(0x03, 7, 1), 17).empty());
}

// docs/profile-fbs.md, Modbus RTU (serial): only the station is answered; unit 0 is broadcast:
// writes are applied with no reply, reads are ignored.
TEST_F(ModbusMap, RtuUnitIdsAndBroadcast) {
    img_.set_word(Area::R, 7, 77);
    EXPECT_EQ(wire::reply_words(rtu(wire::read_pdu(0x03, 7, 1), 1)),
              std::vector<std::uint16_t>{77});
    EXPECT_TRUE(rtu(wire::read_pdu(0x03, 7, 1), 2).empty());
    EXPECT_TRUE(rtu(wire::read_pdu(0x03, 7, 1), 255).empty());
    EXPECT_TRUE(rtu(wire::write_single_pdu(0x06, 7, 1), 2).empty());
    EXPECT_EQ(img_.word(Area::R, 7), 77);

    // Broadcast writes: applied, nothing sent.
    EXPECT_TRUE(rtu(wire::write_single_pdu(0x06, 7, 0x0707), 0).empty());
    EXPECT_EQ(img_.word(Area::R, 7), 0x0707);
    EXPECT_TRUE(rtu(wire::write_registers_pdu(6000, {1, 2}), 0).empty());
    EXPECT_EQ(img_.word(Area::D, 1), 2);
    EXPECT_TRUE(rtu(wire::write_single_pdu(0x05, 2000, 0xFF00), 0).empty());
    EXPECT_TRUE(img_.bit(Area::M, 0));
    EXPECT_TRUE(rtu(wire::write_coils_pdu(0, {true, false, true}), 0).empty());
    EXPECT_TRUE(img_.bit(Area::Y, 2));
    EXPECT_TRUE(rtu({0x16, 0x00, 0x07, 0x00, 0xFF, 0x00, 0x00}, 0).empty());
    EXPECT_EQ(img_.word(Area::R, 7), 0x0007);
    // Broadcast reads and refused broadcasts: nothing sent.
    EXPECT_TRUE(rtu(wire::read_pdu(0x03, 7, 1), 0).empty());
    EXPECT_TRUE(rtu(wire::read_pdu(0x01, 0, 1), 0).empty());
    EXPECT_TRUE(rtu(wire::write_single_pdu(0x06, 4500, 1), 0).empty());
    EXPECT_TRUE(rtu({0x41}, 0).empty());
    EXPECT_TRUE(rtu({0x11}, 0).empty());
    EXPECT_TRUE(rtu({0x08, 0x00, 0x00, 0x12, 0x34}, 0).empty());
    // Exceptions are framed as RTU too.
    EXPECT_EQ(wire::exception_of(rtu(wire::read_pdu(0x03, 4500, 1), 1)), kIllegalAddress);
    const Bytes echo{0x08, 0x00, 0x00, 0x12, 0x34};
    EXPECT_EQ(rtu(echo, 1), echo);
}

// The address map's own table is the manual's (what --print-map prints).
TEST_F(ModbusMap, MapTableMatchesTheManual) {
    const auto& rows = testing::fbs().map().rows();
    ASSERT_EQ(rows.size(), manual_rows().size());
    for (std::size_t i = 0; i < rows.size(); ++i) {
        const auto& s = manual_rows()[i];
        SCOPED_TRACE(s.name);
        EXPECT_EQ(rows[i].table, s.table);
        EXPECT_EQ(rows[i].wire_start, s.first);
        EXPECT_EQ(rows[i].wire_start + rows[i].count - 1, s.last);
        EXPECT_EQ(rows[i].devices.area, s.area);
        EXPECT_EQ(rows[i].devices.start, s.first_device);
        EXPECT_EQ(rows[i].devices.count, rows[i].count);
    }
}

// Config write protection: read_only refuses every write, write_protect the listed ranges.
TEST_F(ModbusMap, ConfigWritePolicy) {
    unit_.set_policy({false, {image::Range{Area::D, 10, 5}}});
    EXPECT_EQ(write_register(6009, 1), 0);
    EXPECT_EQ(write_register(6010, 1), kIllegalAddress);
    EXPECT_EQ(write_registers(6005, std::vector<std::uint16_t>(6, 1)), kIllegalAddress);
    EXPECT_EQ(img_.word(Area::D, 10), 0);
    EXPECT_EQ(write_register(6015, 1), 0);
    EXPECT_EQ(write_register(1000, 1), 0);
    EXPECT_EQ(write_coil(1000, true), kIllegalAddress);  // X stays read-only
    unit_.set_policy({true, {}});
    EXPECT_EQ(write_register(6015, 2), kIllegalAddress);
    EXPECT_EQ(write_coil(0, true), kIllegalAddress);
    EXPECT_EQ(read_exception(0x03, 6015, 1), 0);
    EXPECT_EQ(img_.word(Area::D, 15), 1);
}

}  // namespace
}  // namespace plcemu::modbus

namespace plcemu::modbus {
namespace {

// A profile's own function code: answers with its unit's slave ID and the PDU length.
FunctionReply echo_length(const FunctionRequest& r, PduBuffer out) noexcept {
    out[0] = r.pdu[0];
    out[1] = r.slave_id;
    out[2] = static_cast<std::uint8_t>(r.pdu.size());
    return FunctionReply::pdu(3);
}

// Function codes are a table a profile may extend or cut (docs/architecture.md, one handler per
// code).
TEST_F(ModbusMap, AProfileMayAddOrRefuseFunctionCodes) {
    EXPECT_EQ(wire::exception_of(tcp({0x41, 1, 2})), kIllegalFunction);
    disp_.set_function(0x41, &echo_length);
    EXPECT_EQ(tcp({0x41, 1, 2}), (Bytes{0x41, 1, 3}));
    // Refused: FC 03 now gets exception 01, the others are untouched.
    disp_.set_function(0x03, nullptr);
    EXPECT_EQ(wire::exception_of(tcp(wire::read_pdu(0x03, 0, 1))), kIllegalFunction);
    EXPECT_EQ(wire::exception_of(tcp(wire::read_pdu(0x04, 0, 1))), kIllegalFunction);  // no map
    EXPECT_EQ(wire::exception_of(tcp(wire::read_pdu(0x01, 0, 1))), 0);
    // Codes of 80h and up are never served.
    disp_.set_function(0x90, &echo_length);
    EXPECT_EQ(wire::exception_of(tcp({0x90, 1})), kIllegalFunction);
}

}  // namespace
}  // namespace plcemu::modbus

namespace plcemu::modbus {
namespace {

// A map whose adjacent rows hold other devices (as a VB's D7999 at 7999 and D9000 at 8000): a
// request across them is served as one, and a write lands in every row or, when one part is
// read-only, in none (docs/profile-vb.md, "Modbus map").
class SpanningRows : public ::testing::Test {
protected:
    image::Image img_{testing::fbs_layout()};
    std::unique_ptr<AddressMap> map_ = make_table_map(
        {
            {Table::HoldingRegisters, 0, 10, {image::Area::D, 100, 10}, "", "D100-D109"},
            {Table::HoldingRegisters, 10, 10, {image::Area::R, 200, 10}, "", "R200-R209"},
            {Table::HoldingRegisters,
             20,
             10,
             {image::Area::D, 300, 10},
             "",
             "D300-D309",
             false,
             true},  // read-only
            {Table::Coils, 0, 8, {image::Area::M, 0, 8}, "", "M0-M7"},
            {Table::Coils, 8, 8, {image::Area::Y, 0, 8}, "", "Y0-Y7"},
        },
        {});
    PlcUnit unit_{img_, *map_, {}};
    std::uint8_t station_ = 1;
    Dispatcher disp_{Identity{"V", "M", "1"}};
    wire::Wire wire_{disp_, unit_, station_};

    Bytes tcp(const Bytes& pdu) { return wire_.tcp(1, pdu); }
};

TEST_F(SpanningRows, ReadsAcrossRowsOfOtherDevices) {
    img_.set_word(image::Area::D, 109, 1109);
    img_.set_word(image::Area::R, 200, 200);
    img_.set_word(image::Area::R, 209, 209);
    img_.set_word(image::Area::D, 300, 300);
    const Bytes r = tcp(wire::read_pdu(0x03, 9, 12));
    ASSERT_EQ(wire::exception_of(r), 0);
    const auto w = wire::reply_words(r);
    ASSERT_EQ(w.size(), 12u);
    EXPECT_EQ(w[0], 1109);
    EXPECT_EQ(w[1], 200);
    EXPECT_EQ(w[10], 209);
    EXPECT_EQ(w[11], 300);
    img_.set_bit(image::Area::M, 7, true);
    img_.set_bit(image::Area::Y, 0, true);
    const Bytes b = tcp(wire::read_pdu(0x01, 7, 2));
    EXPECT_EQ(wire::reply_bits(b, 2), (std::vector<bool>{true, true}));
}

TEST_F(SpanningRows, AWriteLandsInEveryRowOrInNone) {
    EXPECT_EQ(wire::exception_of(tcp(wire::write_registers_pdu(9, {1, 2}))), 0);
    EXPECT_EQ(img_.word(image::Area::D, 109), 1);
    EXPECT_EQ(img_.word(image::Area::R, 200), 2);
    // R209 is writable, D300 is not: nothing changes.
    EXPECT_EQ(wire::exception_of(tcp(wire::write_registers_pdu(19, {7, 7}))), 2);
    EXPECT_EQ(img_.word(image::Area::R, 209), 0);
    EXPECT_EQ(wire::exception_of(tcp(wire::write_coils_pdu(7, {true, true}))), 0);
    EXPECT_TRUE(img_.bit(image::Area::M, 7));
    EXPECT_TRUE(img_.bit(image::Area::Y, 0));
}

TEST_F(SpanningRows, AnUnmappedAddressRefusesTheWholeRequest) {
    EXPECT_EQ(wire::exception_of(tcp(wire::read_pdu(0x03, 25, 10))), 2);  // 30 is unmapped
    EXPECT_EQ(wire::exception_of(tcp(wire::read_pdu(0x01, 15, 2))), 2);
    EXPECT_EQ(wire::exception_of(tcp(wire::write_registers_pdu(29, {1, 1}))), 2);
}

}  // namespace
}  // namespace plcemu::modbus
