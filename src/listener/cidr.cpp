#include "cidr.hpp"

namespace plcemu::listener {

bool Cidr::parse(const std::string& text, Cidr& out) {
    const auto slash = text.find('/');
    asio::error_code ec;
    out.network = asio::ip::make_address(text.substr(0, slash), ec);
    if (ec) return false;
    const unsigned max = out.network.is_v4() ? 32 : 128;
    out.prefix = max;
    if (slash != std::string::npos) {
        const std::string p = text.substr(slash + 1);
        if (p.empty() || p.size() > 3) return false;
        unsigned v = 0;
        for (char c : p) {
            if (c < '0' || c > '9') return false;
            v = v * 10 + static_cast<unsigned>(c - '0');
        }
        if (v > max) return false;
        out.prefix = v;
    }
    // "::ffff:10.0.0.0/104" names IPv4 peers: keep it as 10.0.0.0/8, so that it matches them on
    // an IPv4 listener as well as on a dual-stack one.
    if (out.network.is_v6() && out.network.to_v6().is_v4_mapped() && out.prefix >= 96) {
        out.network = asio::ip::make_address_v4(asio::ip::v4_mapped, out.network.to_v6());
        out.prefix -= 96;
    }
    return true;
}

bool Cidr::contains(const asio::ip::address& a) const {
    asio::ip::address addr = a;
    if (addr.is_v6() && addr.to_v6().is_v4_mapped() && network.is_v4()) {
        addr = asio::ip::make_address_v4(asio::ip::v4_mapped, addr.to_v6());
    }
    if (addr.is_v4() != network.is_v4()) return false;
    auto match = [&](const auto& x, const auto& y) {
        unsigned bits = prefix;
        for (std::size_t i = 0; i < x.size() && bits > 0; ++i) {
            const unsigned take = bits >= 8 ? 8 : bits;
            const auto mask = static_cast<std::uint8_t>(0xFF << (8 - take));
            if ((x[i] & mask) != (y[i] & mask)) return false;
            bits -= take;
        }
        return true;
    };
    if (addr.is_v4()) return match(addr.to_v4().to_bytes(), network.to_v4().to_bytes());
    return match(addr.to_v6().to_bytes(), network.to_v6().to_bytes());
}

}  // namespace plcemu::listener
