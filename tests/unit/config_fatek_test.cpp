// The `fatek:` section (docs/configuration.md, Configuration and "Sharing a listener";
// docs/profile-fbs.md, "FATEK protocol"): its defaults, the families that speak it, and the rule
// that one port or line carries one protocol.

#include <gtest/gtest.h>

#include <string>

#include "plcemu/config/config.hpp"
#include "plcemu/config/listeners.hpp"
#include "support/config_errors.hpp"

namespace plcemu::config {
namespace {

void expect_error(const std::string& text, int line, int col, const std::string& needle) {
    SCOPED_TRACE(text);
    testing::expect_config_error(testing::config_failure([&] { parse_plcs(text, "t.yaml"); }),
                                 "t.yaml", line, col, needle);
}

// Each listener is off unless its key is there; port 500 and 9600 7E1 are the defaults.
TEST(ConfigFatek, ListenersAreOffUnlessNamedAndTakeTheFatekDefaults) {
    const Config none = parse_config("profile: fbs\n", "t.yaml");
    EXPECT_FALSE(none.fatek.tcp);
    EXPECT_FALSE(none.fatek.udp);
    EXPECT_FALSE(none.fatek.serial);
    ASSERT_EQ(listeners_of(none).size(), 1u);  // modbus.tcp only

    const Config c = parse_config(
        "profile: fbs\n"
        "fatek:\n"
        "  tcp: {}\n"
        "  udp: {bind: 127.0.0.1, read_only: true}\n"
        "  serial: {device: /dev/ttyS9}\n",
        "t.yaml");
    ASSERT_TRUE(c.fatek.tcp);
    EXPECT_EQ(c.fatek.tcp->port, 500);
    EXPECT_EQ(c.fatek.tcp->bind, "0.0.0.0");
    EXPECT_FALSE(c.fatek.tcp->read_only);
    ASSERT_TRUE(c.fatek.udp);
    EXPECT_EQ(c.fatek.udp->port, 500);
    EXPECT_TRUE(c.fatek.udp->read_only);
    ASSERT_TRUE(c.fatek.serial);
    EXPECT_EQ(c.fatek.serial->baud, 9600);
    EXPECT_EQ(c.fatek.serial->data_bits, 7);
    EXPECT_EQ(c.fatek.serial->parity, 'E');
    EXPECT_EQ(c.fatek.serial->stop_bits, 1);
    const auto l = listeners_of(c);
    ASSERT_EQ(l.size(), 4u);
    EXPECT_EQ(l[1].section, "fatek.tcp");
    EXPECT_EQ(l[1].protocol, "fatek");
    EXPECT_EQ(l[2].carrier, Carrier::Udp);
    EXPECT_EQ(listener_key(l[2]), "udp 127.0.0.1:500");
    EXPECT_EQ(l[3].carrier, Carrier::Serial);

    const Config off = parse_config("profile: fb\nfatek: {tcp: {enabled: false}}\n", "t.yaml");
    EXPECT_FALSE(off.fatek.tcp);
}

// A family that does not speak the protocol refuses its section where it stands, naming those
// that do.
TEST(ConfigFatek, VbRefusesTheSectionNamingTheProfilesThatSpeakIt) {
    expect_error("profile: vb\nfatek:\n  tcp: {port: 500}\n", 3, 3,
                 "fatek: profile vb does not speak FATEK's protocol (profiles fb and fbs do)");
}

// Keys a listener does not take, and bad values, are refused at their place.
TEST(ConfigFatek, BadKeysAndValuesAreRefusedAtTheirPlace) {
    expect_error("profile: fbs\nfatek: {udp: {max_clients: 3}}\n", 2, 15,
                 "unknown key 'max_clients' in fatek.udp");
    expect_error("profile: fbs\nfatek: {tcp: {unknown_unit: silent}}\n", 2, 15,
                 "unknown key 'unknown_unit' in fatek.tcp");
    expect_error("profile: fbs\nfatek: {tcp: {port: 70000}}\n", 2, 21, "fatek.tcp.port");
    expect_error("profile: fbs\nfatek: {serial: {device: /dev/x, parity: Q}}\n", 2, 42,
                 "fatek.serial.parity: expected N, E or O");
    expect_error("profile: fbs\nfatek: {modbus: {}}\n", 2, 9, "unknown key 'modbus' in fatek");
    expect_error("profile: fbs\nmodbus: {tcp: {read_only: true}}\n", 2, 16,
                 "unknown key 'read_only' in modbus.tcp");
}

// One port carries one protocol, within a PLC and across PLCs; a serial line too.
TEST(ConfigFatek, OnePortOrLineCarriesOneProtocol) {
    expect_error("profile: fbs\nmodbus: {tcp: {port: 1500}}\nfatek: {tcp: {port: 1500}}\n", 3, 21,
                 "fatek.tcp.port: 1500 is also this PLC's modbus.tcp port");
    expect_error(
        "profile: fbs\nmodbus: {rtu: {device: /dev/ttyS7}}\nfatek: {serial: {device: "
        "/dev/ttyS7}}\n",
        3, 26, "fatek.serial.device: '/dev/ttyS7' is also this PLC's modbus.rtu");
    expect_error(
        "plcs:\n"
        "  - {profile: fbs, modbus: {tcp: {port: 1600}}}\n"
        "  - {profile: fbs, station: 2, modbus: {tcp: {port: 1601}}, fatek: {tcp: {port: "
        "1600}}}\n",
        3, 81, "fatek.tcp.port: 1600 is also plcs[0]'s modbus.tcp port");
    // TCP and UDP on one number are two listeners.
    EXPECT_NO_THROW(parse_config(
        "profile: fbs\nmodbus: {tcp: {port: 1500}}\nfatek: {udp: {port: 1500}}\n", "t.yaml"));
}

// PLCs may share a FATEK listener by station, agreeing on its settings; the simulator unit does
// not count there.
TEST(ConfigFatek, PlcsShareAFatekListenerByStation) {
    const auto ok = parse_plcs(
        "plcs:\n"
        "  - {profile: fbs, modbus: {tcp: {port: 0}}, fatek: {tcp: {port: 1700}}}\n"
        "  - {profile: fb, station: 2, modbus: {tcp: {port: 0}}, fatek: {tcp: {port: 1700}}}\n",
        "t.yaml");
    EXPECT_EQ(ok.size(), 2u);
    expect_error(
        "plcs:\n"
        "  - {profile: fbs, modbus: {tcp: {port: 0}}, fatek: {serial: {device: /dev/ttyS5}}}\n"
        "  - {profile: fbs, modbus: {tcp: {port: 0}}, fatek: {serial: {device: /dev/ttyS5}}}\n",
        3, 5, "station: 1 is also plcs[0]'s on the shared serial line '/dev/ttyS5'");
    expect_error(
        "plcs:\n"
        "  - {profile: fbs, modbus: {tcp: {port: 0}}, fatek: {udp: {port: 1701}}}\n"
        "  - {profile: fbs, station: 2, modbus: {tcp: {port: 0}}, fatek: {udp: {port: 1701, "
        "read_only: true}}}\n",
        3, 95, "fatek.udp.read_only: differs from plcs[0]'s, which shares the udp listener");
}

}  // namespace
}  // namespace plcemu::config
