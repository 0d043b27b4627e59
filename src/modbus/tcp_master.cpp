#include "tcp_master.hpp"

#include <spdlog/spdlog.h>

#include <algorithm>
#include <array>
#include <cstring>

#include "log_limiter.hpp"
#include "mbap.hpp"

namespace plcemu::modbus {

namespace {

using asio::ip::tcp;
using Clock = std::chrono::steady_clock;

// A slave's faults are logged once per endpoint and cause in a window, then counted
// (docs/profile-vb.md, "Transports: `mbus:`"): a hostile slave must not fill the log.
constexpr std::size_t kLogBurst = 1;
constexpr auto kLogWindow = std::chrono::seconds(2);
// Reconnects after a fault: the first at once (one lie costs only its own transfer), then
// after 100 ms, doubling up to 10 s, until the slave answers a transaction again.
constexpr auto kBackoffFirst = std::chrono::milliseconds(100);
constexpr auto kBackoffMax = std::chrono::seconds(10);
// Bytes of frames answering no request in flight (late replies to abandoned requests, stale
// transaction IDs) taken between two requests to an endpoint; more closes the connection.
constexpr std::size_t kMaxUnasked = 4 * kMaxTcpAdu;

// The wait before the reconnect that follows `faults` faults in a row.
Clock::duration backoff(unsigned faults) {
    if (faults <= 1) return Clock::duration{0};
    Clock::duration d = kBackoffFirst;
    for (unsigned i = 2; i < faults && d < kBackoffMax; ++i) d *= 2;
    return std::min<Clock::duration>(d, kBackoffMax);
}

std::string name_of(const tcp::endpoint& ep) {
    const std::string host = ep.address().to_string();
    return (ep.address().is_v6() ? "[" + host + "]" : host) + ":" + std::to_string(ep.port());
}

// One endpoint's connection. `epoch` tells the handlers of a closed socket from the current
// one's, so that a late completion never touches a connection opened after it.
struct Connection {
    Connection(asio::io_context& io, const tcp::endpoint& ep)
        : peer(ep),
          prefix("mbus: " + name_of(ep) + ": "),
          socket(io),
          retry(io) {}

    tcp::endpoint peer;
    std::string prefix;  // "mbus: 127.0.0.1:502: ", of its log lines
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
    // Bytes of frames that answered nothing since the last request to the endpoint.
    std::size_t unasked = 0;
    // Faults (a bad header, part of a frame left, a flood, a connection lost) since the slave
    // last answered a transaction; the next connect waits until `retry_at`.
    unsigned faults = 0;
    Clock::time_point retry_at{};
    asio::steady_timer retry;  // armed while a transfer waits for `retry_at`
    bool retrying = false;
    // What a transfer that waited for `retry_at` past its deadline ends with: the last fault's
    // outcome (Garbled after bytes that were no frame, TimedOut after a lost connection).
    MasterOutcome held = MasterOutcome::TimedOut;
    LogLimiter limiter{kLogBurst, kLogWindow};
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
        auto frame = std::make_shared<std::vector<std::uint8_t>>(kMbapPrefix + 1 + pdu.size());
        frame->resize(write_mbap(tid, to, pdu, *frame));
        // The deadline runs from the send, whatever the connection is doing (VB manual FNC149:
        // D9129 is how long the slave may take to respond).
        deadline.expires_after(timeout);
        deadline.async_wait(
            [self = shared_from_this(), g = generation](const asio::error_code& ec) {
                if (ec || self->stopped || g != self->generation || !self->active) return;
                self->finish(self->unanswered(), {});
            });
        conn = route[to];
        // No endpoint for this station: it never answers.
        if (conn < 0) return;
        Connection& c = *conns[static_cast<std::size_t>(conn)];
        c.limiter.flush_to_log(Clock::now(), c.prefix);
        c.unasked = 0;
        if (c.open && c.used > 0) {
            // Part of a frame is left from before: a length field lied, and the next reply
            // would be read as the rest of it. A new connection starts in step.
            log(c, spdlog::level::warn, LogCause::FrameLeft,
                "{}{} bytes of no whole frame left; reconnecting", c.prefix, c.used);
            fault(conn, MasterOutcome::Garbled);
        }
        c.queued = std::move(frame);
        c.queued_for = generation;
        if (c.open) {
            send_queued(conn);
        } else {
            connect_when_due(conn);
        }
    }

    // How a transfer that got no reply by its deadline ends: status 5, or, while its endpoint
    // waits to reconnect after a fault, that fault's outcome.
    MasterOutcome unanswered() const {
        if (conn < 0) return MasterOutcome::TimedOut;
        const Connection& c = *conns[static_cast<std::size_t>(conn)];
        return c.retrying ? c.held : MasterOutcome::TimedOut;
    }

    // Connects now, or once the back-off after a fault is over, for the transfer then in flight.
    void connect_when_due(int index) {
        Connection& c = *conns[static_cast<std::size_t>(index)];
        if (c.connecting || c.retrying) return;
        if (Clock::now() >= c.retry_at) {
            connect(index);
            return;
        }
        c.retrying = true;
        c.retry.expires_at(c.retry_at);
        c.retry.async_wait(
            [self = shared_from_this(), index, e = c.epoch](const asio::error_code& ec) {
                Connection& cc = *self->conns[static_cast<std::size_t>(index)];
                if (self->stopped || cc.epoch != e) return;
                cc.retrying = false;
                if (ec) return;
                if (cc.queued && self->active && self->conn == index &&
                    cc.queued_for == self->generation)
                    self->connect(index);
            });
    }

    // Logs about `c` at `level` unless the cause's budget for the endpoint is spent (see
    // LogLimiter); what was not logged is counted in a line at the next transfer after the
    // window.
    template <typename... Args>
    void log(Connection& c,
             spdlog::level::level_enum level,
             LogCause cause,
             spdlog::format_string_t<Args...> fmt,
             Args&&... args) {
        if (c.limiter.allow(cause, Clock::now()))
            spdlog::log(level, fmt, std::forward<Args>(args)...);
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
                self->log(cc, spdlog::level::info, LogCause::Connected, "mbus: connected to {}",
                          name_of(cc.peer));
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
                log(c, spdlog::level::warn, LogCause::BadHeader, "{}bad MBAP header; closing",
                    c.prefix);
                return garbled(index);
            }
            std::array<std::uint8_t, kMaxTcpAdu> frame{};
            std::memcpy(frame.data(), c.buf.data(), f.size);
            std::memmove(c.buf.data(), c.buf.data() + f.size, c.used - f.size);
            c.used -= f.size;
            const std::span<const std::uint8_t> whole{frame.data(), f.size};
            const std::uint16_t id = mbap_transaction(whole);
            // A reply to an abandoned or timed-out transaction is dropped; beyond a few of
            // them, a slave sending what nobody asked for is closed.
            if (!active || conn != index || id != tid) {
                c.unasked += f.size;
                if (c.unasked <= kMaxUnasked) continue;
                log(c, spdlog::level::warn, LogCause::Flood,
                    "{}more than {} bytes not asked for since the last request; closing", c.prefix,
                    kMaxUnasked);
                return garbled(index);
            }
            c.faults = 0;  // the slave answers: its next fault reconnects at once
            const unsigned epoch = c.epoch;
            finish(mbap_unit(whole) == station ? MasterOutcome::Reply : MasterOutcome::Garbled,
                   mbap_pdu(whole));
            if (stopped || c.epoch != epoch) return false;
        }
    }

    // Closes a connection whose bytes cannot be trusted; the transfer on it is status 6.
    bool garbled(int index) {
        const bool ours = active && conn == index;
        fault(index, MasterOutcome::Garbled);
        if (ours) finish(MasterOutcome::Garbled, {});
        return false;
    }

    // Closes a connection the slave misbehaved on, and holds the next connect back (kBackoff*).
    void fault(int index, MasterOutcome held) {
        Connection& c = *conns[static_cast<std::size_t>(index)];
        close(index);
        if (c.faults < 64) ++c.faults;
        c.held = held;
        c.retry_at = Clock::now() + backoff(c.faults);
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
    // 5), and the next transaction to the endpoint opens it again (after the back-off, if it
    // had been open).
    void lost(int index, const asio::error_code& ec) {
        Connection& c = *conns[static_cast<std::size_t>(index)];
        if (!c.open) {
            // Tried again by the next transfer: refused connects are paced by the time-out.
            spdlog::debug("mbus: {}: cannot connect ({})", name_of(c.peer), ec.message());
            close(index);
            return;
        }
        log(c, spdlog::level::warn, LogCause::Disconnected, "{}connection lost ({})", c.prefix,
            ec.message());
        fault(index, MasterOutcome::TimedOut);
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
        c.retrying = false;
        c.retry.cancel();
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
