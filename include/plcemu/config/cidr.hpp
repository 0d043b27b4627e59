#pragma once
// An allow list's entry: an IPv4 or IPv6 network in CIDR notation (docs/operations.md, "Access
// control"). One parser for every view: the config loader refuses what it cannot read, at its
// line and column, and the listeners match their peers against the value it read.

#include <array>
#include <cstdint>
#include <optional>
#include <string>

namespace plcemu::config {

/// A network in CIDR notation.
struct Cidr {
    std::string text;                        ///< as written, for logs and the reload's changes
    std::array<std::uint8_t, 16> network{};  ///< the network address; its first 4 bytes for IPv4
    bool v4 = true;                          ///< an IPv4 network
    unsigned prefix = 0;                     ///< prefix length

    /// Reads "192.168.1.0/24", "10.0.0.1" (a /32), "::1/128". "::ffff:10.0.0.0/104" names IPv4
    /// peers and is kept as 10.0.0.0/8, so that it matches them on an IPv4 listener as well as
    /// on a dual-stack one. Nothing when malformed.
    static std::optional<Cidr> parse(const std::string& text);
    /// True when `address` (4 bytes when `address_v4`, else 16) lies inside; an IPv4-mapped IPv6
    /// address matches IPv4 networks.
    bool contains(const std::uint8_t* address, bool address_v4) const noexcept;

    bool operator==(const Cidr& o) const { return text == o.text; }
};

}  // namespace plcemu::config
