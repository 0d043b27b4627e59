#pragma once
// The allow lists of network listeners: which peers may talk to a listener at all. The entries
// are the config's own values (config::Cidr), read once by the loader.

#include <asio.hpp>

#include "plcemu/config/cidr.hpp"

namespace plcemu::listener {

using config::Cidr;

/// True when the peer `a` lies inside `net` (IPv4-mapped IPv6 peers match IPv4 networks).
bool contains(const Cidr& net, const asio::ip::address& a);

}  // namespace plcemu::listener
