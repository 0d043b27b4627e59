#include "plcemu/config/cidr.hpp"

#include <arpa/inet.h>

#include <algorithm>
#include <cstring>

namespace plcemu::config {

namespace {

// ::ffff:a.b.c.d
bool v4_mapped(const std::uint8_t* a) {
    static constexpr std::uint8_t kPrefix[12] = {0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0xFF, 0xFF};
    return std::memcmp(a, kPrefix, sizeof kPrefix) == 0;
}

}  // namespace

std::optional<Cidr> Cidr::parse(const std::string& text) {
    Cidr out;
    out.text = text;
    const auto slash = text.find('/');
    const std::string address = text.substr(0, slash);
    if (::inet_pton(AF_INET, address.c_str(), out.network.data()) == 1) {
        out.v4 = true;
    } else if (::inet_pton(AF_INET6, address.c_str(), out.network.data()) == 1) {
        out.v4 = false;
    } else {
        return std::nullopt;
    }
    const unsigned max = out.v4 ? 32 : 128;
    out.prefix = max;
    if (slash != std::string::npos) {
        const std::string p = text.substr(slash + 1);
        if (p.empty() || p.size() > 3 || p.find_first_not_of("0123456789") != std::string::npos)
            return std::nullopt;
        const auto v = static_cast<unsigned>(std::stoul(p));
        if (v > max) return std::nullopt;
        out.prefix = v;
    }
    if (!out.v4 && v4_mapped(out.network.data()) && out.prefix >= 96) {
        std::array<std::uint8_t, 16> v4{};
        std::copy_n(out.network.begin() + 12, 4, v4.begin());
        out.network = v4;
        out.v4 = true;
        out.prefix -= 96;
    }
    return out;
}

bool Cidr::contains(const std::uint8_t* address, bool address_v4) const noexcept {
    const std::uint8_t* a = address;
    if (!address_v4 && v4 && v4_mapped(address)) {
        a = address + 12;
        address_v4 = true;
    }
    if (address_v4 != v4) return false;
    unsigned bits = prefix;
    for (std::size_t i = 0; bits > 0; ++i) {
        const unsigned take = std::min(bits, 8u);
        const auto mask = static_cast<std::uint8_t>(0xFF << (8 - take));
        if ((a[i] & mask) != (network[i] & mask)) return false;
        bits -= take;
    }
    return true;
}

}  // namespace plcemu::config
