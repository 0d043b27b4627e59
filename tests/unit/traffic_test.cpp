// What the clients of a PLC asked of it (the console's overview and traffic pages): per client
// its requests and refusals, the last exchanges in order, a client that left no longer listed.

#include "plcemu/listener/traffic.hpp"

#include <gtest/gtest.h>

#include <string>
#include <string_view>

namespace plcemu::listener {
namespace {

Exchange ask(const Client& c, std::uint8_t fc, std::uint8_t error = 0) {
    Exchange e;
    e.client = c.id;
    e.protocol = c.protocol;
    e.function = fc;
    e.error = error;
    e.at = std::chrono::system_clock::time_point(std::chrono::seconds(fc));
    return e;
}

TEST(Traffic, CountsEachClientsRequestsAndRefusals) {
    Traffic t;
    const Client a = make_client("10.0.0.1:5000", "modbus-tcp");
    const Client b = make_client("10.0.0.2:5000", "fatek");
    EXPECT_NE(a.id, b.id);
    t.record(a, ask(a, 3));
    t.record(b, ask(b, 0x46));
    t.record(a, ask(a, 6, 2));
    ASSERT_EQ(t.clients().size(), 2u);
    EXPECT_EQ(t.clients()[0].peer, "10.0.0.1:5000");
    EXPECT_EQ(t.clients()[0].requests, 2u);
    EXPECT_EQ(t.clients()[0].refusals, 1u);
    EXPECT_EQ(t.clients()[0].last, std::chrono::system_clock::time_point(std::chrono::seconds(6)));
    EXPECT_EQ(t.clients()[1].protocol, "fatek");
    EXPECT_EQ(t.peer(b.id), "10.0.0.2:5000");
    t.gone(a.id);
    ASSERT_EQ(t.clients().size(), 1u);
    EXPECT_EQ(t.peer(a.id), "");
    // Its exchanges stay, in order.
    const auto x = t.exchanges();
    ASSERT_EQ(x.size(), 3u);
    EXPECT_EQ(x[0].function, 3);
    EXPECT_EQ(x[2].error, 2);
}

// The ring keeps an exchange in 24 bytes: every field comes back as recorded, the time to the
// millisecond, a 17h's write range beside its read range.
TEST(Traffic, AnExchangeComesBackAsRecordedToTheMillisecond) {
    Traffic t;
    const Client a = make_client("10.0.0.1:5000", "modbus-tcp");
    Exchange e = ask(a, 0x17, 2);
    e.at =
        std::chrono::system_clock::time_point(std::chrono::nanoseconds(1'798'000'123'456'789'012));
    e.unit = 247;
    e.simulator = true;
    e.address = 65535;
    e.count = 125;
    e.write_address = 65534;
    e.write_count = 121;
    t.record(a, e);
    const auto x = t.exchanges();
    ASSERT_EQ(x.size(), 1u);
    EXPECT_EQ(x[0].at,
              std::chrono::system_clock::time_point(std::chrono::milliseconds(1'798'000'123'456)));
    EXPECT_EQ(x[0].client, a.id);
    EXPECT_EQ(x[0].protocol, "modbus-tcp");
    EXPECT_EQ(x[0].unit, 247);
    EXPECT_EQ(x[0].function, 0x17);
    EXPECT_EQ(x[0].error, 2);
    EXPECT_TRUE(x[0].simulator);
    EXPECT_EQ(x[0].address, 65535);
    EXPECT_EQ(x[0].count, 125);
    EXPECT_EQ(x[0].write_address, 65534);
    EXPECT_EQ(x[0].write_count, 121);
}

TEST(Traffic, CountsRequestsByProtocolFunctionAndErrorPastTheClientsThatMadeThem) {
    Traffic t;
    const Client a = make_client("10.0.0.1:5000", "modbus-tcp");
    const Client b = make_client("/dev/ttyUSB0", "modbus-rtu");
    for (int i = 0; i < 3; ++i) t.record(a, ask(a, 3));
    t.record(a, ask(a, 3, 2));
    t.record(b, ask(b, 3));
    t.gone(a.id);  // counts are kept when the client leaves
    t.record(b, ask(b, 3, 2));
    const auto& k = t.counts();
    ASSERT_EQ(k.size(), 4u);
    EXPECT_EQ(k[0].protocol, "modbus-tcp");
    EXPECT_EQ(k[0].function, 3);
    EXPECT_EQ(k[0].error, 0);
    EXPECT_EQ(k[0].count, 3u);
    EXPECT_EQ(k[1].error, 2);
    EXPECT_EQ(k[1].count, 1u);
    EXPECT_EQ(k[2].protocol, "modbus-rtu");
    EXPECT_EQ(k[2].count, 1u);
    EXPECT_EQ(k[3].protocol, "modbus-rtu");
    EXPECT_EQ(k[3].error, 2);
    EXPECT_EQ(k[3].count, 1u);
}

TEST(Traffic, KeepsTheLastExchangesOnly) {
    Traffic t;
    const Client a = make_client("x", "modbus-tcp");
    for (std::size_t i = 0; i < Traffic::kKept + 10; ++i) {
        Exchange e = ask(a, 3);
        e.address = static_cast<std::uint16_t>(i);
        t.record(a, e);
    }
    const auto x = t.exchanges();
    ASSERT_EQ(x.size(), Traffic::kKept);
    EXPECT_EQ(x.front().address, 10);
    EXPECT_EQ(x.back().address, Traffic::kKept + 9);
    EXPECT_EQ(t.clients()[0].requests, Traffic::kKept + 10);
}

// The ring keeps each exchange in fewer bytes (its protocol as a number): every field comes back
// as it was recorded, whichever protocol carried it, its name as a protocol gave it.
TEST(Traffic, KeptExchangesComeBackWholeWhateverCarriedThem) {
    Traffic t;
    const Client a = make_client("10.0.0.1:5000", "modbus-tcp");
    const Client b = make_client("/dev/ttyS0", "fatek", Carrier::Line);
    const std::string rtu = "modbus-rtu";  // a name with an address of its own
    for (std::size_t i = 0; i < Traffic::kKept + 3; ++i) {
        const Client& c = i % 3 == 1 ? b : a;
        Exchange e;
        e.at = std::chrono::system_clock::time_point(std::chrono::milliseconds(1000 + i));
        e.client = c.id;
        e.protocol = i % 3 == 2 ? std::string_view(rtu) : c.protocol;
        e.unit = static_cast<std::uint8_t>(i);
        e.function = static_cast<std::uint8_t>(i * 7);
        e.error = static_cast<std::uint8_t>(i % 5);
        e.simulator = i % 4 == 0;
        e.address = static_cast<std::uint16_t>(65535 - i);
        e.count = static_cast<std::uint16_t>(i * 3);
        t.record(c, e);
    }
    const auto x = t.exchanges();
    ASSERT_EQ(x.size(), Traffic::kKept);
    for (std::size_t k = 0; k < x.size(); ++k) {
        const std::size_t i = k + 3;
        SCOPED_TRACE(i);
        EXPECT_EQ(x[k].at,
                  std::chrono::system_clock::time_point(std::chrono::milliseconds(1000 + i)));
        EXPECT_EQ(x[k].client, i % 3 == 1 ? b.id : a.id);
        EXPECT_EQ(x[k].protocol, i % 3 == 0 ? "modbus-tcp" : i % 3 == 1 ? "fatek" : "modbus-rtu");
        EXPECT_EQ(x[k].unit, static_cast<std::uint8_t>(i));
        EXPECT_EQ(x[k].function, static_cast<std::uint8_t>(i * 7));
        EXPECT_EQ(x[k].error, i % 5);
        EXPECT_EQ(x[k].simulator, i % 4 == 0);
        EXPECT_EQ(x[k].address, 65535 - i);
        EXPECT_EQ(x[k].count, i * 3);
    }
}

}  // namespace
}  // namespace plcemu::listener
