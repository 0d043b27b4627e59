// modbus.tcp.allow entries (docs/operations.md, "Access control").

#include <gtest/gtest.h>

#include "listener/tcp_listener.hpp"

namespace plcemu::listener {
namespace {

bool allows(const std::string& entry, const std::string& peer) {
    Cidr c;
    EXPECT_TRUE(Cidr::parse(entry, c)) << entry;
    return c.contains(asio::ip::make_address(peer));
}

TEST(Cidr, Ipv4MappedEntriesMatchIpv4PeersOnEitherListener) {
    // An IPv4 listener sees 10.1.2.3; a dual-stack one sees ::ffff:10.1.2.3.
    EXPECT_TRUE(allows("::ffff:10.0.0.0/104", "10.1.2.3"));
    EXPECT_TRUE(allows("::ffff:10.0.0.0/104", "::ffff:10.1.2.3"));
    EXPECT_TRUE(allows("::ffff:127.0.0.1", "127.0.0.1"));
    EXPECT_FALSE(allows("::ffff:10.0.0.0/104", "11.0.0.1"));
    EXPECT_FALSE(allows("::ffff:127.0.0.1", "127.0.0.2"));
}

TEST(Cidr, PlainEntries) {
    EXPECT_TRUE(allows("192.168.1.0/24", "192.168.1.77"));
    EXPECT_TRUE(allows("192.168.1.0/24", "::ffff:192.168.1.77"));
    EXPECT_FALSE(allows("192.168.1.0/24", "192.168.2.1"));
    EXPECT_TRUE(allows("::1", "::1"));
    EXPECT_FALSE(allows("::1", "127.0.0.1"));
    Cidr c;
    EXPECT_FALSE(Cidr::parse("10.0.0.0/33", c));
    EXPECT_FALSE(Cidr::parse("::ffff:10.0.0.0/129", c));
}

}  // namespace
}  // namespace plcemu::listener
