// Allow list entries (docs/operations.md, "Access control"): the one parser the config loader
// and the listeners share, and how a listener matches a peer against an entry.

#include <gtest/gtest.h>

#include "listener/cidr.hpp"

namespace plcemu::listener {
namespace {

bool allows(const std::string& entry, const std::string& peer) {
    const auto c = Cidr::parse(entry);
    EXPECT_TRUE(c) << entry;
    return c && contains(*c, asio::ip::make_address(peer));
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
    EXPECT_TRUE(allows("10.0.0.0/0", "203.0.113.9"));  // a /0 takes every IPv4 peer
    EXPECT_FALSE(allows("10.0.0.0/0", "2001:db8::1"));
    EXPECT_TRUE(allows("2001:db8::/32", "2001:db8:ffff::1"));
    EXPECT_FALSE(allows("2001:db8::/33", "2001:db8:8000::1"));
    EXPECT_TRUE(allows("::1", "::1"));
    EXPECT_FALSE(allows("::1", "127.0.0.1"));
}

TEST(Cidr, WhatIsNotACidrIsRefusedAndTheTextIsKept) {
    for (const char* bad : {"10.0.0.0/33", "::ffff:10.0.0.0/129", "10.0.0.0/", "10.0.0.0/8x",
                            "10.0.0.0/0008", "localhost", "10.0.0", "", "/8", "10.0.0.0/-1"}) {
        EXPECT_FALSE(Cidr::parse(bad)) << bad;
    }
    const auto c = Cidr::parse("::ffff:10.0.0.0/104");
    ASSERT_TRUE(c);
    EXPECT_EQ(c->text, "::ffff:10.0.0.0/104");  // as written, for the reload's list of changes
    EXPECT_TRUE(c->v4);
    EXPECT_EQ(c->prefix, 8u);
}

}  // namespace
}  // namespace plcemu::listener
