#include "tcp_server.hpp"

#include "mbap.hpp"

#include <linux/sockios.h>
#include <spdlog/spdlog.h>
#include <sys/ioctl.h>

#include <array>
#include <chrono>
#include <cstring>
#include <system_error>
#include <unordered_set>

namespace plcemu::modbus {

namespace {

using asio::ip::tcp;
using Clock = std::chrono::steady_clock;

constexpr std::size_t kMaxReply = 260;     // largest Modbus TCP ADU
constexpr std::size_t kBufferSize = 4096;  // room for many pipelined requests

std::string peer_name(const tcp::endpoint& ep) {
    return ep.address().to_string() + ":" + std::to_string(ep.port());
}

}  // namespace

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

class Connection;

struct TcpServer::State : std::enable_shared_from_this<TcpServer::State> {
    State(asio::io_context& io_, Dispatcher& d, TcpOptions o)
        : io(io_),
          dispatcher(&d),
          options(std::move(o)),
          acceptor(io_),
          sweep(io_) {}

    void accept();
    void arm_sweep();

    asio::io_context& io;
    Dispatcher* dispatcher;  // replaced on reload; connections keep going
    TcpOptions options;
    tcp::acceptor acceptor;
    asio::steady_timer sweep;
    std::unordered_set<std::shared_ptr<Connection>> connections;
    bool stopped = false;
};

// One client: reads MBAP frames into its own buffer and serves each complete one.
class Connection : public std::enable_shared_from_this<Connection> {
public:
    Connection(tcp::socket s, std::weak_ptr<TcpServer::State> server, std::string peer)
        : socket_(std::move(s)),
          server_(std::move(server)),
          peer_(std::move(peer)),
          last_activity_(Clock::now()) {
        int size = 0;
        socklen_t len = sizeof size;
        if (::getsockopt(socket_.native_handle(), SOL_SOCKET, SO_SNDBUF, &size, &len) == 0) {
            sndbuf_ = static_cast<std::size_t>(size);
        }
    }

    void start() {
        // Non-blocking for good: reads and the replies libmodbus sends on this descriptor never
        // wait (replies are only sent when the send buffer has room, see room_for_reply).
        asio::error_code ec;
        socket_.non_blocking(true, ec);
        read();
    }

    void close(const char* why) {
        if (closed_) return;
        closed_ = true;
        asio::error_code ec;
        socket_.shutdown(tcp::socket::shutdown_both, ec);
        socket_.close(ec);
        spdlog::info("tcp: {} disconnected ({})", peer_, why);
        if (auto s = server_.lock()) s->connections.erase(shared_from_this());
    }

    Clock::time_point last_activity() const { return last_activity_; }
    /// The peer's address ("unspecified" when it could not be read).
    asio::ip::address address() const {
        asio::error_code ec;
        const auto ep = socket_.remote_endpoint(ec);
        return ec ? asio::ip::address() : ep.address();
    }

private:
    void read() {
        if (closed_) return;
        // After a short read, Asio (1.22) marks the socket exhausted and queues the next read
        // without trying it first: one recv per request, issued when epoll says data is there.
        // (A wait-then-recv costs an epoll_ctl per request instead; measured with perf.)
        socket_.async_read_some(
            asio::buffer(buf_.data() + used_, buf_.size() - used_),
            [self = shared_from_this()](const asio::error_code& ec, std::size_t n) {
                if (ec) {
                    self->close(ec == asio::error::eof ? "closed by peer" : "read error");
                    return;
                }
                self->used_ += n;
                self->last_activity_ = Clock::now();
                self->serve_and_continue();
            });
    }

    void serve_and_continue() {
        if (!serve_frames()) return;
        if (waiting_) return;
        read();
    }

    // Serves every complete frame in the buffer. False when the connection was closed.
    bool serve_frames() {
        auto server = server_.lock();
        if (!server || closed_) return false;
        std::size_t off = 0;
        while (true) {
            const std::uint8_t* f = buf_.data() + off;
            const MbapFrame frame = next_mbap_frame({f, used_ - off});
            if (frame.status == MbapStatus::Incomplete) break;
            // SPEC §2: a bad MBAP header closes the connection (and only this one).
            if (frame.status == MbapStatus::Bad) {
                spdlog::debug("tcp: {} bad MBAP header (protocol {}, length {})", peer_,
                              frame.protocol, frame.length);
                close("bad MBAP header");
                return false;
            }
            if (!room_for_reply()) {
                wait_writable();
                break;
            }
            server->dispatcher->serve_tcp(socket_.native_handle(), {f, frame.size});
            unacked_ += kMaxReply;
            off += frame.size;
        }
        if (off > 0) {
            std::memmove(buf_.data(), buf_.data() + off, used_ - off);
            used_ -= off;
        }
        return true;
    }

    // Replies are written straight to the socket; never write one that might not fit in the
    // send buffer (a client that does not read its replies stops being read instead).
    bool room_for_reply() {
        if (unacked_ + kMaxReply <= sndbuf_ / 2) return true;
        int queued = 0;
        if (::ioctl(socket_.native_handle(), SIOCOUTQ, &queued) != 0) return false;
        unacked_ = static_cast<std::size_t>(queued);
        return unacked_ + kMaxReply <= sndbuf_ / 2;
    }

    void wait_writable() {
        waiting_ = true;
        socket_.async_wait(tcp::socket::wait_write,
                           [self = shared_from_this()](const asio::error_code& ec) {
                               self->waiting_ = false;
                               if (ec) {
                                   self->close("write wait failed");
                                   return;
                               }
                               self->unacked_ = 0;
                               int queued = 0;
                               if (::ioctl(self->socket_.native_handle(), SIOCOUTQ, &queued) == 0) {
                                   self->unacked_ = static_cast<std::size_t>(queued);
                               }
                               self->serve_and_continue();
                           });
    }

    tcp::socket socket_;
    std::weak_ptr<TcpServer::State> server_;
    std::string peer_;
    std::array<std::uint8_t, kBufferSize> buf_{};
    std::size_t used_ = 0;
    std::size_t sndbuf_ = 16384;
    std::size_t unacked_ = 0;
    bool waiting_ = false;
    bool closed_ = false;
    Clock::time_point last_activity_;
};

void TcpServer::State::accept() {
    acceptor.async_accept([self = shared_from_this()](const asio::error_code& ec, tcp::socket s) {
        if (self->stopped) return;
        if (ec) {
            if (ec != asio::error::operation_aborted) {
                spdlog::warn("tcp: accept failed: {}", ec.message());
                self->accept();
            }
            return;
        }
        asio::error_code pec;
        const auto ep = s.remote_endpoint(pec);
        const std::string peer = pec ? std::string("?") : peer_name(ep);
        bool allowed = self->options.allow.empty();
        for (const auto& c : self->options.allow)
            allowed = allowed || (!pec && c.contains(ep.address()));
        if (!allowed) {
            spdlog::warn("tcp: {} refused: not in modbus.tcp.allow", peer);
            s.close(pec);
        } else if (static_cast<int>(self->connections.size()) >= self->options.max_clients) {
            spdlog::warn("tcp: {} refused: {} clients already connected (modbus.tcp.max_clients)",
                         peer, self->connections.size());
            s.close(pec);
        } else {
            s.set_option(tcp::no_delay(true), pec);
            spdlog::info("tcp: {} connected", peer);
            auto c = std::make_shared<Connection>(std::move(s), self, peer);
            self->connections.insert(c);
            c->start();
        }
        self->accept();
    });
}

void TcpServer::State::arm_sweep() {
    if (options.idle_timeout_s <= 0 || stopped) return;
    sweep.expires_after(std::chrono::seconds(1));
    sweep.async_wait([self = shared_from_this()](const asio::error_code& ec) {
        if (ec || self->stopped) return;
        const auto limit = Clock::now() - std::chrono::seconds(self->options.idle_timeout_s);
        std::vector<std::shared_ptr<Connection>> idle;
        for (const auto& c : self->connections) {
            if (c->last_activity() < limit) idle.push_back(c);
        }
        for (const auto& c : idle) c->close("idle timeout");
        self->arm_sweep();
    });
}

TcpServer::TcpServer(asio::io_context& io, Dispatcher& dispatcher, TcpOptions options)
    : state_(std::make_shared<State>(io, dispatcher, std::move(options))) {
    // The error names the endpoint: "bind: Address already in use" alone does not say which.
    const std::string where =
        "cannot listen on tcp " + state_->options.bind + ":" + std::to_string(state_->options.port);
    asio::error_code ec;
    const auto addr = asio::ip::make_address(state_->options.bind, ec);
    if (ec) throw std::system_error(ec, where);
    const tcp::endpoint ep(addr, state_->options.port);
    state_->acceptor.open(ep.protocol(), ec);
    if (!ec) state_->acceptor.set_option(tcp::acceptor::reuse_address(true), ec);
    if (!ec) state_->acceptor.bind(ep, ec);
    if (!ec) state_->acceptor.listen(asio::socket_base::max_listen_connections, ec);
    if (ec) throw std::system_error(ec, where);
    state_->accept();
    state_->arm_sweep();
}

TcpServer::~TcpServer() { stop(); }

std::uint16_t TcpServer::port() const {
    asio::error_code ec;
    return state_->acceptor.local_endpoint(ec).port();
}

std::string TcpServer::endpoint() const {
    asio::error_code ec;
    return peer_name(state_->acceptor.local_endpoint(ec));
}

std::size_t TcpServer::connections() const { return state_->connections.size(); }

void TcpServer::set_limits(int max_clients, int idle_timeout_s, std::vector<Cidr> allow) {
    const bool rearm = idle_timeout_s > 0 && state_->options.idle_timeout_s <= 0;
    state_->options.max_clients = max_clients;
    state_->options.idle_timeout_s = idle_timeout_s;
    state_->options.allow = std::move(allow);
    if (rearm) state_->arm_sweep();
    // A peer taken off the allow list loses its connection now, not at its next reconnect.
    if (state_->options.allow.empty()) return;
    std::vector<std::shared_ptr<Connection>> refused;
    for (const auto& c : state_->connections) {
        bool ok = false;
        for (const auto& net : state_->options.allow) ok = ok || net.contains(c->address());
        if (!ok) refused.push_back(c);
    }
    for (const auto& c : refused) c->close("no longer in modbus.tcp.allow");
}

void TcpServer::set_dispatcher(Dispatcher& dispatcher) { state_->dispatcher = &dispatcher; }

void TcpServer::stop() {
    if (state_->stopped) return;
    state_->stopped = true;
    asio::error_code ec;
    state_->acceptor.close(ec);
    state_->sweep.cancel();
    auto conns = state_->connections;
    for (const auto& c : conns) c->close("server stopping");
}

}  // namespace plcemu::modbus
