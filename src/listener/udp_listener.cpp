#include "udp_listener.hpp"

#include <spdlog/spdlog.h>

#include <algorithm>
#include <chrono>
#include <memory>
#include <new>
#include <system_error>
#include <utility>
#include <vector>

#include "modbus/log_limiter.hpp"

namespace plcemu::listener {

using asio::ip::udp;
using modbus::LogCause;
using modbus::LogLimiter;

namespace {

// Refused peers are logged a few at a time, as the TCP listener's are.
constexpr int kLogBurst = 5;
constexpr std::chrono::seconds kLogWindow{10};
// UDP has no connections: a peer is listed as a client while it keeps asking. The peers heard
// most recently are kept, and one silent for UdpOptions::forget_after is no longer listed.
constexpr std::size_t kPeers = 16;
// Answers held at once by a delay fault; beyond it more are dropped.
constexpr std::size_t kMaxHeld = 256;

std::string peer_name(const udp::endpoint& ep) {
    return ep.address().to_string() + ":" + std::to_string(ep.port());
}

}  // namespace

struct UdpListener::State : std::enable_shared_from_this<State> {
    State(asio::io_context& io, StreamProtocol& p, UdpOptions o)
        : socket(io),
          summary(io),
          forget(io),
          protocol(p),
          options(std::move(o)),
          in(p.max_frame() + 1),
          out(p.max_frame()) {}

    void receive() {
        // One byte more than a frame: a longer datagram is seen as too long, not cut to size.
        socket.async_receive_from(
            asio::buffer(in), sender,
            [self = shared_from_this()](const asio::error_code& ec, std::size_t n) {
                if (ec == asio::error::operation_aborted || !self->socket.is_open()) return;
                if (!ec) self->serve(n);
                self->receive();
            });
    }

    void serve(std::size_t n) noexcept {
        if (n > protocol.max_frame()) return;
        if (!allowed(sender.address())) {
            if (limiter.allow(LogCause::DatagramRefused, std::chrono::steady_clock::now())) {
                spdlog::warn("udp {}: ignored a datagram from {}, not in the allow list", name,
                             peer_name(sender));
            } else {
                arm_summary();
            }
            return;
        }
        protocol.units().set_serving(&client_of(sender));
        const std::size_t size = protocol.answer(std::span(in.data(), n), std::span(out));
        protocol.units().set_serving(nullptr);
        const Fate fate = protocol.units().take_fate();
        if (size == 0) return;
        if (fate.delay.count() > 0) {
            hold(fate, size);
            return;
        }
        // A datagram socket's send does not wait for the peer; should the kernel's buffer be
        // full, the reply is lost as on a real network and the master asks again.
        asio::error_code ec;
        socket.send_to(asio::buffer(out.data(), size), sender, 0, ec);
    }

    // What the limiter holds back is summed up by a timer off the request path, armed only
    // while something is held back: each second, so within a second of the window's end.
    void arm_summary() noexcept {
        if (summary_armed || !socket.is_open()) return;
        summary_armed = true;
        summary.expires_after(std::chrono::seconds(1));
        summary.async_wait([self = shared_from_this()](const asio::error_code& ec) {
            self->summary_armed = false;
            if (ec || !self->socket.is_open()) return;
            self->limiter.flush_to_log(std::chrono::steady_clock::now(), self->log_prefix);
            if (self->limiter.holding()) self->arm_summary();
        });
    }

    // Sends an answer of `size` bytes (in out) to the sender after its fate's delay (a
    // communication fault), without holding up the datagrams of others. A flood meanwhile is
    // not all held: the bound is the listener's, whichever peers the held answers are for.
    void hold(const Fate& fate, std::size_t size) noexcept {
        if (held >= kMaxHeld) {
            if (fate.by != nullptr) fate.by->held_over(true);
            return;
        }
        try {
            auto timer = std::make_shared<asio::steady_timer>(socket.get_executor(), fate.delay);
            auto bytes = std::make_shared<std::vector<std::uint8_t>>(
                out.begin(), out.begin() + static_cast<long>(size));
            ++held;
            timer->async_wait(
                [self = shared_from_this(), timer, bytes, to = sender](const asio::error_code& ec) {
                    --self->held;
                    if (ec || !self->socket.is_open()) return;
                    asio::error_code ignored;
                    self->socket.send_to(asio::buffer(*bytes), to, 0, ignored);
                });
        } catch (const std::bad_alloc&) {
            // Lost, as a datagram may be.
            if (fate.by != nullptr) fate.by->held_over(true);
        }
    }

    // The client a peer is listed as; peers silent too long, or the least recent beyond kPeers,
    // are no longer listed.
    const Client& client_of(const udp::endpoint& ep) {
        const auto now = std::chrono::steady_clock::now();
        Peer* hit = nullptr;
        forget_silent(now, &ep);
        for (auto& p : peers) {
            if (p.endpoint == ep) hit = &p;
        }
        if (hit == nullptr) {
            if (peers.size() >= kPeers) {
                auto oldest = std::min_element(peers.begin(), peers.end(), heard_earlier);
                protocol.units().client_gone(oldest->client.id);
                peers.erase(oldest);
            }
            peers.push_back(
                {ep, make_client(peer_name(ep), options.protocol, Carrier::Datagram), now});
            hit = &peers.back();
        }
        hit->last = now;
        if (!forget_armed) arm_forget();
        return hit->client;
    }

    // A peer that goes silent is no longer listed once its minute is over, whether or not
    // another datagram comes: the timer waits for the first peer due to go.
    void arm_forget() {
        if (peers.empty()) return;
        const auto first = std::min_element(peers.begin(), peers.end(), heard_earlier)->last;
        forget_armed = true;
        forget.expires_at(first + options.forget_after + std::chrono::milliseconds(1));
        forget.async_wait([self = shared_from_this()](const asio::error_code& ec) {
            self->forget_armed = false;
            if (ec || !self->socket.is_open()) return;
            self->forget_silent(std::chrono::steady_clock::now(), nullptr);
            self->arm_forget();
        });
    }

    // Unlists the peers silent for options.forget_after, but `keep` (the one heard now).
    void forget_silent(std::chrono::steady_clock::time_point now, const udp::endpoint* keep) {
        std::erase_if(peers, [&](const Peer& p) {
            const bool gone =
                (keep == nullptr || p.endpoint != *keep) && now - p.last > options.forget_after;
            if (gone) protocol.units().client_gone(p.client.id);
            return gone;
        });
    }

    bool allowed(const asio::ip::address& a) const {
        if (options.allow.empty()) return true;
        for (const auto& c : options.allow) {
            if (contains(c, a)) return true;
        }
        return false;
    }

    udp::socket socket;
    asio::steady_timer summary;  // sums up what the limiter held back
    bool summary_armed = false;
    asio::steady_timer forget;  // unlists peers silent for options.forget_after
    bool forget_armed = false;
    StreamProtocol& protocol;
    UdpOptions options;
    std::vector<std::uint8_t> in;
    std::vector<std::uint8_t> out;
    udp::endpoint sender;
    LogLimiter limiter{kLogBurst, kLogWindow};
    std::string name;
    std::string log_prefix;  // "udp 0.0.0.0:500: ", for the limiter's summaries
    struct Peer {
        udp::endpoint endpoint;
        Client client;
        std::chrono::steady_clock::time_point last;
    };
    static bool heard_earlier(const Peer& a, const Peer& b) { return a.last < b.last; }
    std::vector<Peer> peers;  // the peers listed as clients
    std::size_t held = 0;     // answers waiting out a delay fault
};

UdpListener::UdpListener(asio::io_context& io, StreamProtocol& protocol, UdpOptions options)
    : state_(std::make_shared<State>(io, protocol, std::move(options))) {
    // Named as its `listening on` line names it, with its section: "cannot listen on fatek udp
    // 0.0.0.0:500 (fatek.udp)".
    const std::string_view speaks = state_->options.protocol;
    // Appended piece by piece: GCC 12 at -O2 sees a false overlap in `"..." + std::string&&`.
    std::string where = "cannot listen on ";
    if (!speaks.empty()) where.append(speaks).append(" ");
    where.append("udp ").append(state_->options.bind).append(":");
    where += std::to_string(state_->options.port);
    if (!speaks.empty()) where.append(" (").append(speaks).append(".udp)");
    asio::error_code ec;
    const auto addr = asio::ip::make_address(state_->options.bind, ec);
    if (ec) throw std::system_error(ec, where);
    const udp::endpoint ep(addr, state_->options.port);
    state_->socket.open(ep.protocol(), ec);
    if (!ec) state_->socket.bind(ep, ec);
    if (!ec) state_->socket.non_blocking(true, ec);
    if (ec) throw std::system_error(ec, where);
    state_->name = endpoint();
    state_->log_prefix = "udp " + state_->name + ": ";
    state_->receive();
}

UdpListener::~UdpListener() { stop(); }

std::uint16_t UdpListener::port() const {
    asio::error_code ec;
    return state_->socket.local_endpoint(ec).port();
}

std::string UdpListener::endpoint() const {
    asio::error_code ec;
    return peer_name(state_->socket.local_endpoint(ec));
}

void UdpListener::set_allow(std::vector<Cidr> allow) { state_->options.allow = std::move(allow); }

void UdpListener::stop() {
    asio::error_code ec;
    if (state_->socket.is_open()) {
        // What the limiter holds back is said now: no datagram or timer comes after.
        state_->limiter.flush_to_log(std::chrono::steady_clock::now(), state_->log_prefix, true);
    }
    state_->socket.close(ec);
    state_->summary.cancel();
    state_->forget.cancel();
    for (const auto& p : state_->peers) state_->protocol.units().client_gone(p.client.id);
    state_->peers.clear();
}

}  // namespace plcemu::listener
