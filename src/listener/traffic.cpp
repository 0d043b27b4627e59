#include "plcemu/listener/traffic.hpp"

#include <algorithm>

namespace plcemu::listener {

Client make_client(std::string peer, std::string_view protocol, Carrier carrier) {
    static std::uint64_t next = 0;
    return {++next, std::move(peer), protocol, carrier};
}

void Traffic::record(const Client& client, const Exchange& e) {
    if (last_hit_ >= clients_.size() || clients_[last_hit_].id != client.id) {
        const auto it = std::find_if(clients_.begin(), clients_.end(),
                                     [&](const ClientFigures& c) { return c.id == client.id; });
        if (it == clients_.end()) {
            clients_.push_back({client.id, client.peer, client.protocol, 0, 0, {}});
            last_hit_ = clients_.size() - 1;
        } else {
            last_hit_ = static_cast<std::size_t>(it - clients_.begin());
        }
    }
    ClientFigures& c = clients_[last_hit_];
    ++c.requests;
    if (e.error != 0) ++c.refusals;
    c.last = e.at;
    count(e);
    if (!ring_) ring_ = std::make_unique<std::array<Kept, kKept>>();
    const auto simulator = static_cast<std::uint8_t>(e.simulator ? kSimulator : 0);
    const auto ms = std::chrono::duration_cast<std::chrono::milliseconds>(e.at.time_since_epoch());
    constexpr std::uint64_t k48 = (std::uint64_t{1} << 48) - 1;
    (*ring_)[next_] = {static_cast<std::uint64_t>(std::max<std::int64_t>(ms.count(), 0)) & k48,
                       e.write_address,
                       e.client & k48,
                       e.write_count,
                       e.address,
                       e.count,
                       static_cast<std::uint8_t>(protocol_number(e.protocol) | simulator),
                       e.unit,
                       e.function,
                       e.error};
    next_ = (next_ + 1) % kKept;
    size_ = std::min(size_ + 1, kKept);
}

std::uint8_t Traffic::protocol_number(std::string_view protocol) {
    // The names are the protocols' own constants: compared by address first.
    for (std::size_t i = 0; i < protocols_.size(); ++i) {
        const std::string_view p = protocols_[i];
        if ((p.data() == protocol.data() && p.size() == protocol.size()) || p == protocol) {
            return static_cast<std::uint8_t>(i);
        }
    }
    // A PLC is reached by a few protocols (the daemon knows four), far fewer than the number's
    // seven bits hold; past them the last would be named.
    if (protocols_.size() == kSimulator) return kSimulator - 1;
    protocols_.push_back(protocol);
    return static_cast<std::uint8_t>(protocols_.size() - 1);
}

void Traffic::count(const Exchange& e) {
    auto same = [&](const RequestCount& k) {
        return k.function == e.function && k.error == e.error && k.protocol == e.protocol;
    };
    if (last_count_ >= counts_.size() || !same(counts_[last_count_])) {
        const auto it = std::find_if(counts_.begin(), counts_.end(), same);
        if (it == counts_.end()) {
            counts_.push_back({e.protocol, e.function, e.error, 0});
            last_count_ = counts_.size() - 1;
        } else {
            last_count_ = static_cast<std::size_t>(it - counts_.begin());
        }
    }
    ++counts_[last_count_].count;
}

void Traffic::gone(std::uint64_t client) noexcept {
    std::erase_if(clients_, [&](const ClientFigures& c) { return c.id == client; });
    last_hit_ = 0;
}

std::vector<Exchange> Traffic::exchanges() const {
    std::vector<Exchange> v;
    v.reserve(size_);
    for (std::size_t i = 0; i < size_; ++i) {
        const Kept& k = (*ring_)[(next_ + kKept - size_ + i) % kKept];  // size_ > 0: made
        const std::chrono::system_clock::time_point at{std::chrono::milliseconds(k.at_ms)};
        v.push_back({at, k.client, protocols_[k.protocol & ~kSimulator], k.unit, k.function,
                     k.error, (k.protocol & kSimulator) != 0, k.address, k.count,
                     static_cast<std::uint16_t>(k.write_address),
                     static_cast<std::uint16_t>(k.write_count)});
    }
    return v;
}

std::string_view Traffic::peer(std::uint64_t client) const {
    for (const auto& c : clients_) {
        if (c.id == client) return c.peer;
    }
    return {};
}

}  // namespace plcemu::listener
