#include "tcp_master.hpp"

#include <spdlog/spdlog.h>

#include <algorithm>
#include <array>
#include <cstring>

#include "mbap.hpp"

namespace plcemu::modbus {

namespace {

using asio::ip::tcp;

std::string name_of(const tcp::endpoint& ep) {
    const std::string host = ep.address().to_string();
    return (ep.address().is_v6() ? "[" + host + "]" : host) + ":" + std::to_string(ep.port());
}

// One endpoint's connection. `epoch` tells the handlers of a closed socket from the current
// one's, so that a late completion never touches a connection opened after it.
struct Connection {
    Connection(asio::io_context& io, const tcp::endpoint& ep)
        : peer(ep),
          socket(io) {}

    tcp::endpoint peer;
    tcp::socket socket;
    unsigned epoch = 0;
    bool open = false;
    bool connecting = false;
    bool writing = false;
    // The frame of the transaction `queued_for` that waits for the connection or for the write
    // before it; it is not sent once that transaction has ended.
    std::shared_ptr<std::vector<std::uint8_t>> queued;
    unsigned queued_for = 0;
    // Room for one whole frame beside a partial one: frames are at most kMaxTcpAdu bytes.
    std::array<std::uint8_t, 2 * kMaxTcpAdu> buf{};
    std::size_t used = 0;
};

}  // namespace

struct TcpMasterState : std::enable_shared_from_this<TcpMasterState> {
    explicit TcpMasterState(asio::io_context& io)
        : deadline(io) {}

    void transact(std::uint8_t to,
                  std::span<const std::uint8_t> pdu,
                  std::chrono::milliseconds timeout,
                  MasterDone d) {
        if (stopped) return;
        cancel();
        active = true;
        station = to;
        done = std::move(d);
        ++tid;
        const auto length = static_cast<std::uint16_t>(pdu.size() + 1);
        // Sized once and filled in place: GCC 12 at -O2 takes two inserts into a reserved
        // vector for writes past its end (-Warray-bounds, -Wstringop-overflow).
        auto frame = std::make_shared<std::vector<std::uint8_t>>(kMbapPrefix + length);
        auto& f = *frame;
        f[0] = static_cast<std::uint8_t>(tid >> 8);
        f[1] = static_cast<std::uint8_t>(tid & 0xFF);
        f[4] = static_cast<std::uint8_t>(length >> 8);
        f[5] = static_cast<std::uint8_t>(length & 0xFF);
        f[kMbapPrefix] = to;
        std::copy(pdu.begin(), pdu.end(), f.begin() + kMbapPrefix + 1);
        // The deadline runs from the send, whatever the connection is doing (VB manual FNC149:
        // D9129 is how long the slave may take to respond).
        deadline.expires_after(timeout);
        deadline.async_wait(
            [self = shared_from_this(), g = generation](const asio::error_code& ec) {
                if (ec || self->stopped || g != self->generation || !self->active) return;
                self->finish(MasterOutcome::TimedOut, {});
            });
        conn = route[to];
        // No endpoint for this station: it never answers.
        if (conn < 0) return;
        Connection& c = *conns[static_cast<std::size_t>(conn)];
        if (c.open && c.used > 0) {
            // Part of a frame is left from before: a length field lied, and the next reply
            // would be read as the rest of it. A new connection starts in step.
            spdlog::warn("mbus: {}: {} bytes of no whole frame left; reconnecting", name_of(c.peer),
                         c.used);
            close(conn);
        }
        c.queued = std::move(frame);
        c.queued_for = generation;
        if (c.open) {
            send_queued(conn);
        } else if (!c.connecting) {
            connect(conn);
        }
    }

    void cancel() noexcept {
        active = false;
        done = nullptr;
        ++generation;
        deadline.cancel();
    }

    void stop() noexcept {
        if (stopped) return;
        stopped = true;
        cancel();
        for (std::size_t i = 0; i < conns.size(); ++i) close(static_cast<int>(i));
    }

    void connect(int index) {
        Connection& c = *conns[static_cast<std::size_t>(index)];
        c.connecting = true;
        c.socket.async_connect(
            c.peer, [self = shared_from_this(), index, e = c.epoch](const asio::error_code& ec) {
                Connection& cc = *self->conns[static_cast<std::size_t>(index)];
                if (self->stopped || cc.epoch != e) return;
                cc.connecting = false;
                if (ec) {
                    // Refused or unreachable: the transaction times out; the next one tries again.
                    self->lost(index, ec);
                    return;
                }
                cc.open = true;
                asio::error_code ignored;
                cc.socket.set_option(tcp::no_delay(true), ignored);
                spdlog::info("mbus: connected to {}", name_of(cc.peer));
                self->read(index);
                self->send_queued(index);
            });
    }

    // Writes the queued frame unless a write is under way (a frame already begun goes out whole,
    // so the stream stays framed) or its transaction has ended (an abandoned write never reaches
    // the slave).
    void send_queued(int index) {
        Connection& c = *conns[static_cast<std::size_t>(index)];
        if (c.writing || !c.queued) return;
        auto frame = std::move(c.queued);
        c.queued.reset();
        if (!active || c.queued_for != generation || conn != index) return;
        c.writing = true;
        asio::async_write(c.socket, asio::buffer(*frame),
                          [self = shared_from_this(), index, frame, e = c.epoch](
                              const asio::error_code& ec, std::size_t) {
                              Connection& cc = *self->conns[static_cast<std::size_t>(index)];
                              if (self->stopped || cc.epoch != e) return;
                              cc.writing = false;
                              if (ec) {
                                  self->lost(index, ec);
                                  return;
                              }
                              self->send_queued(index);
                          });
    }

    void read(int index) {
        Connection& c = *conns[static_cast<std::size_t>(index)];
        c.socket.async_read_some(asio::buffer(c.buf.data() + c.used, c.buf.size() - c.used),
                                 [self = shared_from_this(), index, e = c.epoch](
                                     const asio::error_code& ec, std::size_t n) {
                                     Connection& cc = *self->conns[static_cast<std::size_t>(index)];
                                     if (self->stopped || cc.epoch != e) return;
                                     if (ec) {
                                         self->lost(index, ec);
                                         return;
                                     }
                                     cc.used += n;
                                     if (self->frames(index)) self->read(index);
                                 });
    }

    // Takes the whole frames received; false when the connection was closed for garbage or by
    // the callback. Each frame leaves the buffer before its outcome is handed on, and a bad
    // header closes the connection first: the callback may start a transfer or stop the port.
    bool frames(int index) {
        Connection& c = *conns[static_cast<std::size_t>(index)];
        for (;;) {
            const MbapFrame f = next_mbap_frame({c.buf.data(), c.used});
            if (f.status == MbapStatus::Incomplete) return true;
            if (f.status == MbapStatus::Bad) {
                // No frame boundary can be trusted after a bad header.
                spdlog::warn("mbus: {}: bad MBAP header; closing", name_of(c.peer));
                const bool ours = active && conn == index;
                close(index);
                if (ours) finish(MasterOutcome::Garbled, {});
                return false;
            }
            std::array<std::uint8_t, kMaxTcpAdu> frame{};
            std::memcpy(frame.data(), c.buf.data(), f.size);
            std::memmove(c.buf.data(), c.buf.data() + f.size, c.used - f.size);
            c.used -= f.size;
            const auto id = static_cast<std::uint16_t>(frame[0] << 8 | frame[1]);
            // A reply to an abandoned or timed-out transaction is dropped.
            if (active && conn == index && id == tid) {
                const unsigned epoch = c.epoch;
                finish(
                    frame[kMbapPrefix] == station ? MasterOutcome::Reply : MasterOutcome::Garbled,
                    {frame.data() + kMbapPrefix + 1, f.size - kMbapPrefix - 1});
                if (stopped || c.epoch != epoch) return false;
            }
        }
    }

    void finish(MasterOutcome outcome, std::span<const std::uint8_t> pdu) {
        active = false;
        ++generation;
        deadline.cancel();
        MasterDone d = std::move(done);
        done = nullptr;
        if (d) d(outcome, pdu);
    }

    // A connection that failed or closed: the transaction on it waits for its deadline (status
    // 5), and the next transaction to the endpoint opens it again.
    void lost(int index, const asio::error_code& ec) {
        Connection& c = *conns[static_cast<std::size_t>(index)];
        if (c.open)
            spdlog::warn("mbus: {}: connection lost ({})", name_of(c.peer), ec.message());
        else
            spdlog::debug("mbus: {}: cannot connect ({})", name_of(c.peer), ec.message());
        close(index);
    }

    void close(int index) noexcept {
        Connection& c = *conns[static_cast<std::size_t>(index)];
        ++c.epoch;
        asio::error_code ignored;
        c.socket.close(ignored);
        c.open = false;
        c.connecting = false;
        c.writing = false;
        c.queued.reset();
        c.used = 0;
    }

    std::string description() const {
        std::string s;
        for (const auto& c : conns) s += (s.empty() ? "tcp " : ", ") + name_of(c->peer);
        return s.empty() ? "tcp (no endpoint)" : s;
    }

    std::vector<std::unique_ptr<Connection>> conns;
    std::array<int, 256> route{};  // station → connection, -1: none
    asio::steady_timer deadline;
    bool active = false;  // a transaction waits for its outcome
    int conn = -1;        // its connection
    std::uint8_t station = 0;
    std::uint16_t tid = 0;
    unsigned generation = 0;  // tells a deadline of an earlier transaction from this one's
    MasterDone done;
    bool stopped = false;
};

TcpMaster::TcpMaster(asio::io_context& io, TcpMasterOptions options)
    : SharedStateTransport(std::make_shared<TcpMasterState>(io)) {
    auto index_of = [&](const tcp::endpoint& ep) {
        for (std::size_t i = 0; i < state_->conns.size(); ++i) {
            if (state_->conns[i]->peer == ep) return static_cast<int>(i);
        }
        state_->conns.push_back(std::make_unique<Connection>(io, ep));
        return static_cast<int>(state_->conns.size() - 1);
    };
    // One connection per endpoint, however many stations share it.
    const int fallback = options.fallback ? index_of(*options.fallback) : -1;
    state_->route.fill(fallback);
    for (const auto& [station, ep] : options.routes) state_->route[station] = index_of(ep);
}

TcpMaster::~TcpMaster() = default;

}  // namespace plcemu::modbus
