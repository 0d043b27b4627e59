#include "cidr.hpp"

namespace plcemu::listener {

bool contains(const Cidr& net, const asio::ip::address& a) {
    if (a.is_v4()) return net.contains(a.to_v4().to_bytes().data(), true);
    return net.contains(a.to_v6().to_bytes().data(), false);
}

}  // namespace plcemu::listener
