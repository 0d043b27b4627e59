// The process's listeners (docs/configuration.md, "Sharing a listener"; docs/operations.md,
// reloads): opened for real PLCs from a `plcs:` config on 127.0.0.1, then a reload's two halves,
// stage() and apply(), with a plain socket to tell whether a port listens. A new port is a fresh
// listener and the old one closes; the same port with new limits keeps its listener (and its
// clients) and takes the limits; a port that cannot be had fails stage() and changes nothing.

#include "daemon/listeners.hpp"

#include <gtest/gtest.h>

#include <asio.hpp>
#include <chrono>
#include <cstdint>
#include <cstdio>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "fatek/checksum.hpp"
#include "plcemu/config/config.hpp"
#include "plcemu/daemon/plc.hpp"
#include "simulator/simulator_unit.hpp"
#include "support/fake_time.hpp"
#include "support/socket_client.hpp"
#include "support/wire.hpp"

namespace plcemu::daemon {
namespace {

// One PLC seated as the daemon seats it (Host::seat()): its station, dispatcher, unit and
// simulator unit.
struct Member {
    explicit Member(const config::Config& c)
        : config(c),
          plc(config),
          time(plc.engine()),
          sim(plc.plant(), time) {}

    listener::Seat seat() {
        listener::Seat s;
        s.label = config.label;
        s.station = &plc.engine().station();
        s.dispatcher = &plc.dispatcher();
        s.unit = &plc.unit();
        s.simulator_unit = static_cast<std::uint8_t>(config.simulator.unit);
        s.simulator = config.simulator.unit != 0 ? &sim : nullptr;
        s.engine = &plc.engine();
        s.protected_ranges = &plc.unit().protected_ranges();
        return s;
    }

    config::Config config;
    Plc plc;
    testing::FakeTime time;
    simulator::SimulatorUnit sim;
};

// A port of 127.0.0.1 nothing listens on (the kernel's pick, released).
std::uint16_t free_port() {
    asio::io_context io;
    asio::ip::tcp::acceptor a(io, {asio::ip::make_address("127.0.0.1"), 0});
    return a.local_endpoint().port();
}

// Two PLCs, "a" (station 1, R0 = 11) and "b" (station 2, R0 = 22), each with its own simulator
// unit, on the TCP listeners 127.0.0.1:`pa` and :`pb` with `max_clients` (one listener when the
// ports are equal and not 0).
std::string two_plcs(std::uint16_t pa, std::uint16_t pb, int max_clients = 64) {
    auto entry = [&](const char* name, int station, std::uint16_t port, int r0) {
        return "  - {name: " + std::string(name) +
               ", profile: fbs, station: " + std::to_string(station) +
               ", simulator: {unit: " + std::to_string(200 + station) +
               "}, init: {R0: " + std::to_string(r0) +
               "},\n     modbus: {tcp: {bind: 127.0.0.1, port: " + std::to_string(port) +
               ", max_clients: " + std::to_string(max_clients) + "}}}\n";
    };
    return "plcs:\n" + entry("a", 1, pa, 11) + entry("b", 2, pb, 22);
}

// The PLCs of a config and the process's listeners, on one event loop.
class ListenersTest : public ::testing::Test {
protected:
    ~ListenersTest() override { listeners_.stop(); }

    static std::vector<config::Config> configs(const std::string& text) {
        return config::parse_plcs(text, "t.yaml");
    }
    static std::vector<std::unique_ptr<Member>> build(const std::vector<config::Config>& cs) {
        std::vector<std::unique_ptr<Member>> v;
        for (const auto& c : cs) v.push_back(std::make_unique<Member>(c));
        return v;
    }
    std::vector<ListenerMember> members() {
        std::vector<ListenerMember> v;
        for (auto& m : plcs_) v.push_back({&m->config, m->seat()});
        return v;
    }

    void open(const std::string& text) {
        plcs_ = build(configs(text));
        listeners_.open(members());
    }
    // A reload as the daemon does it: stage(), the new PLCs, apply(). False when stage() fails
    // (then nothing changed).
    bool reload(const std::string& text) {
        const std::vector<config::Config> next = configs(text);
        if (!listeners_.stage(next, Listeners::plan(next))) return false;
        auto old = std::move(plcs_);
        plcs_ = build(next);
        listeners_.apply(members());
        return true;
    }

    // What a reload to `text` would be refused for, and the unit IDs that would clash, as the
    // daemon asks (with the configs' plan).
    std::string refusal(const std::string& text) const {
        const auto next = configs(text);
        return listeners_.refusal(next, *Listeners::plan(next));
    }
    std::string unit_clash(const std::vector<config::Config>& next,
                           const std::vector<std::uint8_t>& stations) const {
        return listeners_.unit_clash(next, stations, *Listeners::plan(next));
    }

    // The port of the PLC at `index`'s TCP listener, from describe_all() (", tcp 127.0.0.1:PORT").
    std::uint16_t port_of(std::size_t index) const {
        const std::string d = listeners_.describe_all().at(index);
        const std::string head = ", tcp 127.0.0.1:";
        EXPECT_EQ(d.rfind(head, 0), 0u) << d;
        if (d.rfind(head, 0) != 0) return 0;
        return static_cast<std::uint16_t>(std::stoi(d.substr(head.size())));
    }

    // A client connected to 127.0.0.1:`port`; not open when nothing listens there.
    asio::ip::tcp::socket connect(std::uint16_t port) {
        asio::ip::tcp::socket s(io_);
        asio::error_code ec;
        s.connect({asio::ip::make_address("127.0.0.1"), port}, ec);
        if (ec) s.close();
        return s;
    }
    bool listening(std::uint16_t port) { return connect(port).is_open(); }

    // Holding register 0 of `unit` read over `s` (FC03), or -1 when no reply came in 2 s or the
    // connection closed.
    int read_r0(asio::ip::tcp::socket& s, std::uint8_t unit) {
        const std::vector<std::uint8_t> pdu = testing::read_pdu(0x03, 0, 1);
        std::vector<std::uint8_t> adu{
            0x00, 0x07, 0x00, 0x00, 0x00, static_cast<std::uint8_t>(pdu.size() + 1), unit};
        adu.insert(adu.end(), pdu.begin(), pdu.end());
        asio::error_code ec;
        asio::write(s, asio::buffer(adu), ec);
        if (ec) return -1;
        const std::string reply = testing::read_bytes(io_, s, 11);  // MBAP 7, 03, 02, value
        if (reply.size() < 11) return -1;
        EXPECT_EQ(static_cast<std::uint8_t>(reply[6]), unit);
        EXPECT_EQ(reply[7], 0x03);
        return static_cast<std::uint8_t>(reply[9]) << 8 | static_cast<std::uint8_t>(reply[10]);
    }
    // Holding register 0 of `unit` read on a new connection to 127.0.0.1:`port`, or -1 when
    // nothing listens there or no reply came.
    int r0_at(std::uint16_t port, std::uint8_t unit) {
        auto s = connect(port);
        return s.is_open() ? read_r0(s, unit) : -1;
    }
    // True when the listener closed `s` within 2 s.
    bool closed(asio::ip::tcp::socket& s) { return testing::closed(io_, s); }

    std::vector<std::unique_ptr<Member>> plcs_;  // outlive the listeners that seat them
    asio::io_context io_;
    listener::Census census_;
    Listeners listeners_{io_, census_};
};

TEST_F(ListenersTest, OpensAListenerPerPlcOnPortZeroEachServingItsOwnPlc) {
    open(two_plcs(0, 0));
    const std::uint16_t pa = port_of(0);
    const std::uint16_t pb = port_of(1);
    ASSERT_NE(pa, 0);
    ASSERT_NE(pb, 0);
    EXPECT_NE(pa, pb);
    auto a = connect(pa);
    auto b = connect(pb);
    ASSERT_TRUE(a.is_open());
    ASSERT_TRUE(b.is_open());
    EXPECT_EQ(read_r0(a, 1), 11);
    EXPECT_EQ(read_r0(b, 2), 22);
    // Each listener seats one PLC: the other's station is nobody there.
    EXPECT_EQ(listeners_.holder(0, 2), "");
    EXPECT_EQ(listeners_.holder(0, 201),
              "its own simulator unit on tcp 127.0.0.1:" + std::to_string(pa));
}

// A port-0 listener's key is the PLC and section, not the address: a new bind is still a new
// listener (it was kept on the old address, the reload logging the change).
TEST_F(ListenersTest, APortZeroListenerMovesToANewAddress) {
    open(two_plcs(0, 0));
    const std::uint16_t pa = port_of(0);
    std::string text = two_plcs(0, 0);
    text.replace(text.find("bind: 127.0.0.1"), 15, "bind: 0.0.0.0");
    ASSERT_TRUE(reload(text));
    const std::string d = listeners_.describe_all().at(0);
    EXPECT_EQ(d.rfind(", tcp 0.0.0.0:", 0), 0u) << d;
    EXPECT_EQ(d.find("127.0.0.1:" + std::to_string(pa)), std::string::npos) << d;
}

TEST_F(ListenersTest, ANewPortIsAFreshListenerAndTheOldPortCloses) {
    const std::uint16_t p1 = free_port();
    open(two_plcs(p1, 0));
    ASSERT_EQ(port_of(0), p1);
    const std::uint16_t pb = port_of(1);
    ASSERT_TRUE(listening(p1));
    const std::uint16_t p2 = free_port();
    ASSERT_NE(p1, p2);
    ASSERT_TRUE(reload(two_plcs(p2, 0)));
    EXPECT_EQ(listeners_.describe_all().at(0), ", tcp 127.0.0.1:" + std::to_string(p2));
    EXPECT_FALSE(listening(p1));
    auto a = connect(p2);
    ASSERT_TRUE(a.is_open());
    EXPECT_EQ(read_r0(a, 1), 11);
    // The other PLC's own port-0 listener is kept.
    EXPECT_EQ(port_of(1), pb);
    auto b = connect(pb);
    EXPECT_EQ(read_r0(b, 2), 22);
}

TEST_F(ListenersTest, TheSamePortWithNewLimitsKeepsTheListenerAndItsClients) {
    const std::uint16_t p = free_port();
    open(two_plcs(p, p, 4));
    auto first = connect(p);
    auto second = connect(p);
    ASSERT_EQ(read_r0(first, 1), 11);
    ASSERT_EQ(read_r0(second, 2), 22);  // both served: 2 of 4 clients
    ASSERT_TRUE(reload(two_plcs(p, p, 1)));
    EXPECT_EQ(listeners_.describe_all().at(0), ", tcp 127.0.0.1:" + std::to_string(p));
    EXPECT_EQ(listeners_.describe_all().at(1), ", tcp 127.0.0.1:" + std::to_string(p));
    // The kept listener's clients stay connected and reach the new PLCs...
    EXPECT_EQ(read_r0(first, 1), 11);
    EXPECT_EQ(read_r0(second, 2), 22);
    // ... and max_clients 1 applies: a third client is turned away.
    auto third = connect(p);
    ASSERT_TRUE(third.is_open());  // the kernel's accept queue takes it; the listener closes it
    EXPECT_TRUE(closed(third));
    // The kept listener counts on, for the metrics: 2 accepted and open, 1 refused.
    const auto figures = listeners_.connections();
    ASSERT_EQ(figures.size(), 1u);
    EXPECT_EQ(figures[0].protocol, "modbus-tcp");
    EXPECT_EQ(figures[0].endpoint, "127.0.0.1:" + std::to_string(p));
    EXPECT_EQ(figures[0].open, 2u);
    EXPECT_EQ(figures[0].accepted, 2u);
    EXPECT_EQ(figures[0].refused, 1u);
}

TEST_F(ListenersTest, APortThatCannotBeHadFailsStageAndChangesNothing) {
    const std::uint16_t p1 = free_port();
    open(two_plcs(p1, 0));
    const std::uint16_t pb = port_of(1);
    asio::io_context other;
    asio::ip::tcp::acceptor taken(other, {asio::ip::make_address("127.0.0.1"), 0});
    const std::uint16_t busy = taken.local_endpoint().port();
    EXPECT_FALSE(reload(two_plcs(busy, 0)));
    EXPECT_EQ(listeners_.describe_all().at(0), ", tcp 127.0.0.1:" + std::to_string(p1));
    EXPECT_EQ(port_of(1), pb);
    auto a = connect(p1);
    ASSERT_TRUE(a.is_open());
    EXPECT_EQ(read_r0(a, 1), 11);
    // A later reload that can be had goes through.
    taken.close();
    EXPECT_TRUE(reload(two_plcs(busy, 0)));
    EXPECT_EQ(listeners_.describe_all().at(0), ", tcp 127.0.0.1:" + std::to_string(busy));
    EXPECT_FALSE(listening(p1));
}

TEST_F(ListenersTest, APortAnotherPlcLeavesIsTakenAndASwapGoesThrough) {
    const std::uint16_t p1 = free_port();
    const std::uint16_t p2 = free_port();
    const std::uint16_t p3 = free_port();
    open(two_plcs(p1, p2));
    // b takes a's port in the reload that moves a elsewhere: a's listener closes first.
    ASSERT_TRUE(reload(two_plcs(p3, p1)));
    EXPECT_EQ(port_of(0), p3);
    EXPECT_EQ(port_of(1), p1);
    EXPECT_FALSE(listening(p2));
    EXPECT_EQ(r0_at(p1, 2), 22);
    // Each takes the other's port.
    ASSERT_TRUE(reload(two_plcs(p1, p3)));
    EXPECT_EQ(port_of(0), p1);
    EXPECT_EQ(port_of(1), p3);
    EXPECT_EQ(r0_at(p1, 1), 11);
    // A port held outside the daemon still fails the stage, and the listeners it closed to try
    // come back: b keeps p3 although a's new config asked for a port nobody gives up.
    asio::io_context other;
    asio::ip::tcp::acceptor taken(other, {asio::ip::make_address("127.0.0.1"), 0});
    const std::uint16_t busy = taken.local_endpoint().port();
    EXPECT_FALSE(reload(two_plcs(p3, busy)));
    EXPECT_EQ(port_of(0), p1);
    EXPECT_EQ(port_of(1), p3);
    EXPECT_EQ(r0_at(p3, 2), 22);
}

TEST_F(ListenersTest, APlcLeftOnItsPreviousConfigKeepsThatConfigsListeners) {
    const std::uint16_t pa = free_port();
    const std::uint16_t pb = free_port();
    open(two_plcs(pa, pb));
    // b's new config adds a FATEK UDP listener, but b could not be built on it and runs on its
    // previous config (the daemon's Host::apply returned no PLC): apply() is told so.
    std::string text = two_plcs(pa, pb);
    const std::string b_tcp = "port: " + std::to_string(pb) + ", max_clients: 64}}";
    const auto at = text.find(b_tcp);
    ASSERT_NE(at, std::string::npos);
    text.insert(at + b_tcp.size(), ", fatek: {udp: {enabled: true, bind: 127.0.0.1, port: 0}}");
    const std::vector<config::Config> next = configs(text);
    ASSERT_TRUE(listeners_.stage(next, Listeners::plan(next)));
    std::vector<std::unique_ptr<Member>> previous;
    previous.push_back(std::exchange(plcs_[0], std::make_unique<Member>(next[0])));
    listeners_.apply(members(), false);
    // No UDP listener for b, whose config has none; both still answer.
    EXPECT_EQ(listeners_.describe_all().at(1), ", tcp 127.0.0.1:" + std::to_string(pb));
    EXPECT_EQ(r0_at(pb, 2), 22);
    EXPECT_EQ(r0_at(pa, 1), 11);
    // The next reload compares with what runs: to the same config, it opens b's UDP listener.
    ASSERT_TRUE(reload(text));
    EXPECT_NE(listeners_.describe_all().at(1).find(", fatek udp 127.0.0.1:"), std::string::npos)
        << listeners_.describe_all().at(1);
}

// `text` with PLC a's entry given a FATEK UDP listener on the kernel's port with `udp` (its
// bind and access), and `init` in place of its init.
std::string with_udp_on_a(std::string text,
                          const std::string& init = "init: {R0: 11}",
                          const std::string& udp = "bind: 127.0.0.1") {
    const std::string a_init = "init: {R0: 11}";
    const auto at = text.find(a_init);
    EXPECT_NE(at, std::string::npos);
    text.replace(at, a_init.size(), init + ", fatek: {udp: {enabled: true, port: 0, " + udp + "}}");
    return text;
}

// R0 of station 1 read with FATEK's command 46h in one datagram to 127.0.0.1:`port`, or -1 when
// no answer came in 300 ms.
int fatek_r0_over_udp(asio::io_context& io, std::uint16_t port) {
    std::string request = "014601R00000";
    const std::string head = "\x02" + request;
    char hex[3];
    std::snprintf(
        hex, sizeof hex, "%02X",
        fatek::checksum({reinterpret_cast<const std::uint8_t*>(head.data()), head.size()}));
    request = head + hex + "\x03";
    asio::ip::udp::socket client(io, asio::ip::udp::v4());
    client.send_to(asio::buffer(request), {asio::ip::make_address("127.0.0.1"), port});
    std::string got(64, '\0');
    std::size_t n = 0;
    asio::ip::udp::endpoint from;
    client.async_receive_from(asio::buffer(got), from,
                              [&](const asio::error_code& ec, std::size_t k) {
                                  if (!ec) n = k;
                              });
    io.restart();
    io.run_for(std::chrono::milliseconds(300));
    // "<STX>01460" (no error) then R0 in four hex digits, its checksum, ETX.
    if (n != 13 || got.compare(0, 6,
                               "\x02"
                               "01460") != 0)
        return -1;
    return std::stoi(got.substr(6, 4), nullptr, 16);
}

TEST_F(ListenersTest, AnUnchangedUdpListenerGoesOnThroughAReloadServingTheNewPlcs) {
    const std::uint16_t pa = free_port();
    const std::uint16_t pb = free_port();
    open(with_udp_on_a(two_plcs(pa, pb)));
    const std::string udp = ", fatek udp 127.0.0.1:";
    const std::string before = listeners_.describe_all().at(0);
    ASSERT_NE(before.find(udp), std::string::npos) << before;
    const auto port =
        static_cast<std::uint16_t>(std::stoi(before.substr(before.find(udp) + udp.size())));
    EXPECT_EQ(fatek_r0_over_udp(io_, port), 11);
    // Every PLC is built anew (a's R0 preset changes); the listener's settings do not: the same
    // socket (the kernel's port, which a new one would not keep) serves the new PLC, not the
    // one the reload freed.
    ASSERT_TRUE(reload(with_udp_on_a(two_plcs(pa, pb), "init: {R0: 33}")));
    EXPECT_EQ(listeners_.describe_all().at(0), before);
    EXPECT_EQ(fatek_r0_over_udp(io_, port), 33);
    EXPECT_EQ(r0_at(pa, 1), 33);
    // Its access changes in place, on the same port: 127.0.0.1 is no longer allowed.
    ASSERT_TRUE(reload(
        with_udp_on_a(two_plcs(pa, pb), "init: {R0: 33}", "bind: 127.0.0.1, allow: [127.0.0.2]")));
    EXPECT_EQ(listeners_.describe_all().at(0), before);
    EXPECT_EQ(fatek_r0_over_udp(io_, port), -1);
    // A new address is a new socket, though the key of a port-0 listener does not hold it.
    ASSERT_TRUE(reload(with_udp_on_a(two_plcs(pa, pb), "init: {R0: 33}", "bind: 0.0.0.0")));
    const std::string after = listeners_.describe_all().at(0);
    EXPECT_NE(after.find(", fatek udp 0.0.0.0:"), std::string::npos) << after;
}

TEST_F(ListenersTest, ChangingWhichPlcsShareAListenerIsRefused) {
    const std::uint16_t p = free_port();
    open(two_plcs(p, p));
    const std::string why =
        "plcs[0] (a): the PLCs sharing its tcp listener changed; restart "
        "plcemud to apply it";
    EXPECT_EQ(refusal(two_plcs(p, free_port())), why);
    EXPECT_EQ(refusal(two_plcs(p, 0)), why);
    // The same PLCs on the same listener, or on another one together, can be applied.
    EXPECT_EQ(refusal(two_plcs(p, p, 8)), "");
    const std::uint16_t q = free_port();
    EXPECT_EQ(refusal(two_plcs(q, q)), "");
}

TEST_F(ListenersTest, SeparatePlcsThatComeToShareAListenerAreRefused) {
    open(two_plcs(0, 0));
    const std::uint16_t p = free_port();
    EXPECT_EQ(refusal(two_plcs(p, p)),
              "plcs[0] (a): the PLCs sharing its tcp listener changed; restart plcemud to apply "
              "it");
    EXPECT_EQ(refusal(two_plcs(p, 0)), "");
}

TEST_F(ListenersTest, UnitClashNamesThePlcsAndTheListener) {
    const std::uint16_t p = free_port();
    open(two_plcs(p, p));
    const auto next = configs(two_plcs(p, p));
    const std::string where = " on the shared tcp listener 127.0.0.1:" + std::to_string(p);
    EXPECT_EQ(unit_clash(next, {1, 2}), "");
    EXPECT_EQ(unit_clash(next, {1, 1}),
              "plcs[1] (b): its station 1 (in force: set through R4055; the config says 2) is "
              "also plcs[0] (a)'s station 1" +
                  where);
    EXPECT_EQ(unit_clash(next, {202, 2}),
              "plcs[0] (a): its station 202 (in force: set through R4055; the config says 1) is "
              "also plcs[1] (b)'s simulator unit" +
                  where);
    EXPECT_EQ(unit_clash(next, {201, 2}),
              "plcs[0] (a): its station 201 (in force: set through R4055; the config says 1) is "
              "also its simulator.unit");
    // On listeners of their own, two PLCs may answer one unit ID.
    EXPECT_EQ(unit_clash(configs(two_plcs(0, 0)), {1, 1}), "");
}

TEST_F(ListenersTest, HolderNamesWhatElseAnswersAUnitOnThePlcsListeners) {
    const std::uint16_t p = free_port();
    open(two_plcs(p, p));
    const std::string on = " on tcp 127.0.0.1:" + std::to_string(p);
    EXPECT_EQ(listeners_.holder(0, 2), "plcs[1] (b)'s station" + on);
    EXPECT_EQ(listeners_.holder(1, 1), "plcs[0] (a)'s station" + on);
    EXPECT_EQ(listeners_.holder(0, 201), "its own simulator unit" + on);
    EXPECT_EQ(listeners_.holder(0, 202), "plcs[1] (b)'s simulator unit" + on);
    EXPECT_EQ(listeners_.holder(0, 1), "");  // its own station is not "something else"
    EXPECT_EQ(listeners_.holder(0, 9), "");
}

TEST_F(ListenersTest, DescribeListsOnlyOpenListenersAndStopClosesThem) {
    open(
        "plcs:\n"
        "  - {name: a, profile: fbs, modbus: {tcp: {bind: 127.0.0.1, port: 0}}}\n"
        "  - {name: b, profile: fbs, station: 2, modbus: {tcp: {enabled: false}}}\n");
    const std::uint16_t pa = port_of(0);
    EXPECT_EQ(listeners_.describe_all().at(1), "");
    EXPECT_TRUE(listening(pa));
    listeners_.stop();
    EXPECT_FALSE(listening(pa));
}

}  // namespace
}  // namespace plcemu::daemon
