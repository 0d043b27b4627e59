#pragma once
// The allow lists of network listeners: which peers may talk to a listener at all.

#include <asio.hpp>
#include <string>

namespace plcemu::listener {

/// An IPv4/IPv6 network in CIDR notation.
struct Cidr {
    asio::ip::address network;  ///< network address
    unsigned prefix = 0;        ///< prefix length

    /// Parses "192.168.1.0/24", "10.0.0.1", "::1/128". Returns false when malformed.
    static bool parse(const std::string& text, Cidr& out);
    /// True when `a` lies inside the network (IPv4-mapped IPv6 peers match IPv4 networks).
    bool contains(const asio::ip::address& a) const;
};

}  // namespace plcemu::listener
