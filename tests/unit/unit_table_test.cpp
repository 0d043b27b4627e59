// The unit table of a listener several PLCs share, as the Modbus protocols use it
// (docs/configuration.md, "Sharing a listener"): Modbus over serial line §2.2 (a request goes to
// the slave whose address it carries; a broadcast, address 0, is executed by every slave and
// answered by none; no other slave answers), Modbus TCP implementation guide §4.4.1.2 (units 0 and
// 255 and units without a device behind a gateway).

#include <gtest/gtest.h>

#include <array>
#include <cstdint>
#include <memory>
#include <vector>

#include "plcemu/listener/unit_table.hpp"
#include "plcemu/image/image.hpp"
#include "plcemu/modbus/dispatcher.hpp"
#include "plcemu/modbus/plc_unit.hpp"
#include "support/profiles.hpp"
#include "support/wire.hpp"

namespace plcemu::modbus {
namespace {

using plcemu::testing::exception_of;
using plcemu::testing::read_pdu;
using plcemu::testing::reply_words;
using plcemu::testing::Wire;
using plcemu::testing::write_single_pdu;

constexpr std::uint16_t kD0 = 6000;  // fbs: holding 6000 is D0

// One PLC: its image, unit and dispatcher, and a wire straight to the dispatcher to look at it.
struct Station {
    explicit Station(std::uint8_t s)
        : station(s) {}
    image::Image img{testing::fbs_layout()};
    PlcUnit unit{img, testing::fbs().map(), {}};
    std::uint8_t station;
    Dispatcher disp{Identity{"FATEK", "FBs-24MC", "9.9.9"}};
    Wire direct{disp, unit, station};
    // A second unit behind the PLC (the simulator unit's place), when set.
    Unit* sim = nullptr;
    std::uint8_t sim_unit = 0;

    listener::Seat seat() { return {"", &station, &disp, &unit, sim_unit, sim}; }

    std::uint16_t d0() { return reply_words(direct.rtu(station, read_pdu(0x03, kD0, 1))).at(0); }
};

class SharedLine : public ::testing::Test {
protected:
    std::vector<listener::Seat> seats() {
        std::vector<listener::Seat> v;
        for (auto& s : plcs_) v.push_back(s->seat());
        return v;
    }
    std::array<std::unique_ptr<Station>, 3> plcs_{
        std::make_unique<Station>(1), std::make_unique<Station>(2), std::make_unique<Station>(3)};
    Wire wire_{seats()};
};

TEST_F(SharedLine, EachStationAnswersOnlyItsOwnRequests) {
    EXPECT_TRUE(wire_.rtu(2, write_single_pdu(0x06, kD0, 222)).size() == 5);
    EXPECT_TRUE(wire_.rtu(3, write_single_pdu(0x06, kD0, 333)).size() == 5);
    EXPECT_EQ(plcs_[0]->d0(), 0);
    EXPECT_EQ(plcs_[1]->d0(), 222);
    EXPECT_EQ(plcs_[2]->d0(), 333);
    EXPECT_EQ(reply_words(wire_.rtu(3, read_pdu(0x03, kD0, 1))), std::vector<std::uint16_t>{333});
}

TEST_F(SharedLine, ABroadcastReachesEveryStationAndIsAnsweredByNone) {
    EXPECT_TRUE(wire_.rtu(0, write_single_pdu(0x06, kD0, 77)).empty());
    for (auto& s : plcs_) EXPECT_EQ(s->d0(), 77);
    EXPECT_EQ(wire_.rtu_units().stats().broadcasts, 1u);
}

TEST_F(SharedLine, AStationNobodyHasIsSilenceOnTheLine) {
    EXPECT_TRUE(wire_.rtu(9, read_pdu(0x03, kD0, 1)).empty());
    EXPECT_EQ(wire_.rtu_units().stats().unrouted, 1u);
}

TEST_F(SharedLine, RoutesByTheLiveStation) {
    // FBs manual: a master may change the station through R4055; the line follows at once.
    plcs_[1]->station = 5;
    EXPECT_TRUE(wire_.rtu(2, read_pdu(0x03, kD0, 1)).empty());
    EXPECT_EQ(wire_.rtu(5, write_single_pdu(0x06, kD0, 55)).size(), 5u);
    EXPECT_EQ(plcs_[1]->d0(), 55);
}

TEST_F(SharedLine, TcpRoutesByUnitAndRefusesTheRestWithGatewayTargetFailed) {
    EXPECT_EQ(wire_.tcp(2, write_single_pdu(0x06, kD0, 2)).size(), 5u);
    EXPECT_EQ(plcs_[1]->d0(), 2);
    EXPECT_EQ(plcs_[0]->d0(), 0);
    // Unit 9: nobody's; 0 and 255 name no single PLC behind a shared listener.
    for (const int unit : {9, 0, 255}) {
        EXPECT_EQ(exception_of(wire_.tcp(static_cast<std::uint8_t>(unit), read_pdu(0x03, kD0, 1))),
                  0x0B)
            << unit;
    }
    EXPECT_EQ(wire_.tcp_units().stats().unrouted, 3u);
    wire_.set_unknown_unit(listener::UnknownUnit::Silent);
    EXPECT_TRUE(wire_.tcp(9, read_pdu(0x03, kD0, 1)).empty());
    EXPECT_TRUE(wire_.tcp(0, read_pdu(0x03, kD0, 1)).empty());
}

TEST_F(SharedLine, ASimulatorUnitGoesToItsPlc) {
    // A second unit behind PLC 3 under ID 200 (the simulator unit's place): its own image.
    image::Image other{testing::fbs_layout()};
    PlcUnit second{other, testing::fbs().map(), {}};
    plcs_[2]->sim = &second;
    plcs_[2]->sim_unit = 200;
    Wire wire{seats()};
    EXPECT_EQ(wire.rtu(200, write_single_pdu(0x06, kD0, 9)).size(), 5u);
    EXPECT_EQ(plcs_[2]->d0(), 0);
    Dispatcher look{Identity{}};
    Wire w{look, second, plcs_[2]->station};
    EXPECT_EQ(reply_words(w.tcp(3, read_pdu(0x03, kD0, 1))), std::vector<std::uint16_t>{9});
}

TEST(OwnListener, OnePlcGetsUnitsZeroAnd255AndTheUnknownUnitPolicy) {
    // A listener of its own keeps the single-PLC rules: TCP units 0 and 255 are the device
    // itself, an unknown unit gets the PLC's own policy.
    Station s(1);
    Wire wire{{s.seat()}};
    EXPECT_EQ(wire.tcp(0, write_single_pdu(0x06, kD0, 4)).size(), 5u);
    EXPECT_EQ(reply_words(wire.tcp(255, read_pdu(0x03, kD0, 1))), std::vector<std::uint16_t>{4});
    EXPECT_EQ(exception_of(wire.tcp(9, read_pdu(0x03, kD0, 1))), 0x0B);
    wire.set_unknown_unit(listener::UnknownUnit::Silent);
    EXPECT_TRUE(wire.tcp(9, read_pdu(0x03, kD0, 1)).empty());
    EXPECT_EQ(wire.tcp_units().stats().unrouted, 2u);
    // Over RTU, 0 is a broadcast (applied, never answered) and 255 is nobody.
    EXPECT_TRUE(wire.rtu(0, write_single_pdu(0x06, kD0, 5)).empty());
    EXPECT_EQ(s.d0(), 5);
    EXPECT_TRUE(wire.rtu(255, read_pdu(0x03, kD0, 1)).empty());
}

TEST(UnitTableFind, NamesTheSeatAndTheIdItAnswersAs) {
    Station a(4);
    Station b(9);
    image::Image other{testing::fbs_layout()};
    PlcUnit sim{other, testing::fbs().map(), {}};
    b.sim = &sim;
    b.sim_unit = 200;
    listener::UnitTable t;
    t.assign({a.seat(), b.seat()});
    EXPECT_EQ(t.find(4).seat, &t.seats()[0]);
    EXPECT_FALSE(t.find(4).simulator);
    const listener::Hit h = t.find(200);
    EXPECT_EQ(h.seat, &t.seats()[1]);
    EXPECT_TRUE(h.simulator);
    EXPECT_EQ(h.answer_as, 200);
    // Shared: "the device itself" is nobody; a simulator unit ID without a unit is nobody.
    EXPECT_EQ(t.find(0, true).seat, nullptr);
    EXPECT_EQ(t.find(255, true).seat, nullptr);
    b.sim = nullptr;
    t.assign({a.seat(), b.seat()});
    EXPECT_EQ(t.find(200).seat, nullptr);
    EXPECT_EQ(t.stats().unrouted, 3u);
    // Alone: the device itself is the PLC, answering as its station.
    t.assign({a.seat()});
    EXPECT_EQ(t.find(255, true).answer_as, 4);
}

}  // namespace
}  // namespace plcemu::modbus
