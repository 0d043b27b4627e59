#include "plcemu/listener/traffic.hpp"

#include <algorithm>

namespace plcemu::listener {

Client make_client(std::string peer, std::string_view protocol) {
    static std::uint64_t next = 0;
    return {++next, std::move(peer), protocol};
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
    ring_[next_] = e;
    next_ = (next_ + 1) % kKept;
    size_ = std::min(size_ + 1, kKept);
}

void Traffic::gone(std::uint64_t client) noexcept {
    std::erase_if(clients_, [&](const ClientFigures& c) { return c.id == client; });
    last_hit_ = 0;
}

std::vector<Exchange> Traffic::exchanges() const {
    std::vector<Exchange> v;
    v.reserve(size_);
    for (std::size_t i = 0; i < size_; ++i) v.push_back(ring_[(next_ + kKept - size_ + i) % kKept]);
    return v;
}

std::string_view Traffic::peer(std::uint64_t client) const {
    for (const auto& c : clients_) {
        if (c.id == client) return c.peer;
    }
    return {};
}

}  // namespace plcemu::listener
