// What the fuzz harnesses (tests/fuzz) found, kept as unit tests of the ordinary build. Their
// inputs are also replayed by scripts/fuzz.sh from tests/fuzz/regressions/.

#include <gtest/gtest.h>

#include <cstdint>
#include <vector>

#include "support/profiles.hpp"
#include "plcemu/config/config.hpp"
#include "plcemu/image/image.hpp"
#include "plcemu/modbus/address_map.hpp"
#include "plcemu/modbus/dispatcher.hpp"
#include "plcemu/modbus/plc_unit.hpp"
#include "support/wire.hpp"

namespace plcemu {
namespace {

using Bytes = std::vector<std::uint8_t>;

class FuzzFindings : public ::testing::Test {
protected:
    image::Image img_{testing::fbs_layout()};
    modbus::PlcUnit unit_{img_, testing::fbs().map(), {}};
    std::uint8_t station_ = 1;
    modbus::Dispatcher disp_{modbus::Identity{"FATEK", "FBs-24MC", "9.9.9"}};
    testing::Wire wire_{disp_, unit_, station_};
};

// regressions/fuzz_tcp_request/exception-fc-high-bit: libmodbus adds 80h to the function code
// of an exception, which wrapped DAh round to 5Ah, a reply that looks like a normal one.
// docs/profile-fbs.md, Modbus map: unknown function codes get exception 01, other unit IDs 0Bh;
// the code keeps its high bit.
TEST_F(FuzzFindings, ExceptionToAFunctionCodeWithTheHighBitKeepsIt) {
    EXPECT_EQ(wire_.tcp(1, {0xDA}), (Bytes{0xDA, 0x01}));
    EXPECT_EQ(wire_.tcp(0xFB, {0xDA}), (Bytes{0xDA, 0x0B}));
    EXPECT_EQ(wire_.tcp(1, {0x80, 0x00}), (Bytes{0x80, 0x01}));
    // Codes below 80h are unchanged: 41h → C1h.
    EXPECT_EQ(wire_.tcp(1, {0x41, 0x00}), (Bytes{0xC1, 0x01}));
}

// regressions/fuzz_rtu_frame/exception-fc-high-bit: the same over RTU, with a correct CRC.
TEST_F(FuzzFindings, RtuExceptionToAFunctionCodeWithTheHighBitKeepsIt) {
    EXPECT_EQ(wire_.rtu(1, {0xAE}), (Bytes{0xAE, 0x01}));
    EXPECT_EQ(wire_.rtu(0, {0xAE}), Bytes{});  // broadcast: never answered
}

// regressions/fuzz_config/init-sequence-use-after-scope.yaml: iterating an `init:` list read
// through a yaml-cpp iterator proxy that had already gone (ASan: stack-use-after-scope).
TEST(FuzzFindingsConfig, InitListValuesAreReadWhole) {
    const config::Config c =
        config::parse_config("profile: fbs\ninit:\n  R100: [1, 2, 3]\n  D0: [4]\n", "t.yaml");
    ASSERT_EQ(c.init.size(), 2u);
    EXPECT_EQ(c.init[0].values, (std::vector<std::uint16_t>{1, 2, 3}));
    EXPECT_EQ(c.init[1].values, (std::vector<std::uint16_t>{4}));
}

}  // namespace
}  // namespace plcemu
