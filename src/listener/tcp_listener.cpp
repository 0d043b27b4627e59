#include "tcp_listener.hpp"

#include "modbus/log_limiter.hpp"
#include "plcemu/listener/traffic.hpp"

#include <netinet/in.h>
#include <netinet/tcp.h>
#include <spdlog/spdlog.h>
#include <sys/socket.h>

#include <algorithm>
#include <array>
#include <cerrno>
#include <chrono>
#include <cstring>
#include <system_error>
#include <unordered_set>
#include <utility>
#include <vector>

namespace plcemu::listener {

using modbus::LogCause;
using modbus::LogLimiter;

namespace {

using asio::ip::tcp;
using Clock = std::chrono::steady_clock;

// Room for many pipelined requests; a protocol's frames are at most a quarter of it (a protocol
// with sessions: its largest request fills at most half of a buffer sized for it).
constexpr std::size_t kBufferSize = 4096;
// What a connection reads into until a read fills it (the client sends more than one request
// at a time, or a large one): a client asking one request at a time, as SCADA polling does,
// never needs more, and 4,900 of them would hold 17 MB more (docs/performance.md).
constexpr std::size_t kFirstBuffer = 512;
// What a session may have queued for a client that does not take it (live updates): beyond it
// the client is too far behind and is closed.
constexpr std::size_t kMaxQueued = 4 << 20;
// Frames served per turn before the other connections, and the scans, get theirs (round-robin);
// a turn also ends once its answers reach kBytesPerTurn: a large answer (a console's ten
// minutes of loop history, 150-200 kB) costs the loop in proportion, and sixteen of them
// pipelined held the scans and every other client for a third of a second.
constexpr std::size_t kFramesPerTurn = 16;
constexpr std::size_t kBytesPerTurn = std::size_t{64} * 1024;
// At max_clients, a connection stuck this long gives way to a new one (as does one silent for
// TcpOptions::evict_silent).
constexpr auto kEvictStuck = std::chrono::seconds(1);
// Keepalive: a peer that vanished (cable, power) is found after 60 + 3 x 10 s of silence.
constexpr int kKeepIdleS = 60;
constexpr int kKeepIntervalS = 10;
constexpr int kKeepCount = 3;
// Per-cause log budget: lines per window, then one summary line.
constexpr std::size_t kLogBurst = 50;
constexpr auto kLogWindow = std::chrono::seconds(10);
// Back-off while accept() runs out of descriptors.
constexpr auto kAcceptBackoffFirst = std::chrono::milliseconds(50);
constexpr auto kAcceptBackoffMax = std::chrono::seconds(1);
// An episode of running out of descriptors ends once accepts have worked this long: clients that
// each get in by evicting another are one episode, not a "pausing"/"accepting again" pair each.
constexpr auto kAcceptCalm = std::chrono::seconds(10);

std::string peer_name(const tcp::endpoint& ep) {
    return ep.address().to_string() + ":" + std::to_string(ep.port());
}

void set_keepalive(tcp::socket& s) {
    asio::error_code ec;
    s.set_option(asio::socket_base::keep_alive(true), ec);
    // Asio has no option types for the keepalive timings.
    const int fd = s.native_handle();
    ::setsockopt(fd, IPPROTO_TCP, TCP_KEEPIDLE, &kKeepIdleS, sizeof kKeepIdleS);
    ::setsockopt(fd, IPPROTO_TCP, TCP_KEEPINTVL, &kKeepIntervalS, sizeof kKeepIntervalS);
    ::setsockopt(fd, IPPROTO_TCP, TCP_KEEPCNT, &kKeepCount, sizeof kKeepCount);
}

}  // namespace

class Connection;

struct TcpListener::State : std::enable_shared_from_this<TcpListener::State> {
    State(asio::io_context& io_, StreamProtocol& p, TcpOptions o)
        : io(io_),
          protocol(&p),
          options(std::move(o)),
          acceptor(io_),
          sweep(io_),
          accept_retry(io_),
          accept_calm(io_) {}

    void accept();
    void accept_failed(const asio::error_code& ec);
    /// Opens the acceptor on `bound` (at start, and when refusing ends); false when it cannot.
    bool open_acceptor(asio::error_code& ec);
    /// Follows the PLCs' fault refuse_connections: closes the acceptor while every PLC on the
    /// listener refuses (connects then fail at once, as to a host with no listener), opens it
    /// again when one no longer does.
    void follow_refusal();
    void arm_sweep();
    void check_connections();
    /// Makes room for a new client when every slot is taken by one that is stuck or silent.
    bool evict_one(Clock::time_point now);
    /// Logs at `level` unless the cause's budget is spent (see LogLimiter).
    template <typename... Args>
    void log(spdlog::level::level_enum level,
             LogCause cause,
             spdlog::format_string_t<Args...> fmt,
             Args&&... args) {
        if (limiter.allow(cause, Clock::now()))
            spdlog::log(level, fmt, std::forward<Args>(args)...);
    }

    asio::io_context& io;
    StreamProtocol* protocol;  // what the connections speak
    TcpOptions options;
    tcp::acceptor acceptor;
    asio::steady_timer sweep;
    asio::steady_timer accept_retry;
    asio::steady_timer accept_calm;  // ends an episode of failed accepts (kAcceptCalm)
    std::unordered_set<std::shared_ptr<Connection>> connections;
    LogLimiter limiter{kLogBurst, kLogWindow};
    std::uint64_t accept_failures = 0;  // in the current episode of running out of descriptors
    Clock::time_point accept_failing_since{};
    bool accept_calming = false;           // accepts work again; the episode ends at accept_calm
    Clock::time_point accept_calmed_at{};  // when accepts worked again
    Clock::duration accept_backoff{};
    std::uint64_t accepted = 0;    // connections taken since the listener opened
    std::uint64_t refused = 0;     // connections closed at accept
    tcp::endpoint bound;           // where it listens (the port chosen when 0 was asked)
    bool refusing = false;         // closed by the fault refuse_connections
    bool relisten_failed = false;  // opening it again failed (said once)
    bool stopped = false;
};

// A connection's buffer once it has been filled.
std::size_t full_buffer(std::size_t max_frame) { return std::max(kBufferSize, 2 * max_frame); }

// One client: reads its protocol's frames into its own buffer, serves a few complete ones per turn
// and writes their replies. While replies are waiting for the client to take them, it is not read.
class Connection : public std::enable_shared_from_this<Connection>, public Outlet {
public:
    Connection(tcp::socket s,
               std::weak_ptr<TcpListener::State> server,
               std::string peer,
               std::size_t max_frame,
               std::string_view protocol)
        : max_frame_(max_frame),
          socket_(std::move(s)),
          server_(std::move(server)),
          peer_(std::move(peer)),
          client_(make_client(peer_, protocol)),
          buf_(std::min(kFirstBuffer, full_buffer(max_frame))),
          last_request_(Clock::now()),
          last_traffic_(last_request_),
          ticks_(socket_.get_executor()),
          hold_(socket_.get_executor()) {}

    // Outlet: what a session says outside its answers.
    bool send(std::span<const std::uint8_t> bytes) override {
        if (closed_) return false;
        // While a write is under way its buffer must not move: later bytes wait beside it.
        std::vector<std::uint8_t>& to = writing_ ? pending_ : out_;
        if (out_.size() + pending_.size() + bytes.size() > kMaxQueued) {
            close("not taking what it is sent");
            return false;
        }
        to.insert(to.end(), bytes.begin(), bytes.end());
        // Pushed bytes are traffic: the client is not idle while it takes them (idle_timeout_s).
        // They are no request: a stream opened and left to run is silent, and gives its slot to
        // a new client when every one is taken (64 event streams held every slot of the console
        // for as long as their client wished).
        last_traffic_ = Clock::now();
        if (!writing_ && !serving_) write();
        return !closed_;
    }
    void tick_every(std::chrono::milliseconds period) override {
        tick_period_ = period;
        ticks_.cancel();
        if (period.count() > 0) arm_tick();
    }
    const std::string& peer() const override { return peer_; }

    void start(StreamProtocol& protocol) {
        session_ = protocol.open(*this);
        // A protocol that answers in place writes one frame at a time into reply_.
        if (!session_) reply_.resize(max_frame_);
        // Non-blocking for good: a reply that does not fit is left to an asynchronous write.
        asio::error_code ec;
        socket_.non_blocking(true, ec);
        // A blocking socket would let one slow reader stop the loop: better no connection.
        if (ec) {
            close("cannot make the socket non-blocking");
            return;
        }
        read();
    }

    void close(const char* why) {
        if (closed_) return;
        closed_ = true;
        // The session goes first: it may hold a place in its protocol (a subscription).
        session_.reset();
        ticks_.cancel();
        hold_.cancel();
        asio::error_code ec;
        if (reset_) {
            // No FIN: a zero linger makes the close send RST.
            socket_.set_option(asio::socket_base::linger(true, 0), ec);
        } else {
            socket_.shutdown(tcp::socket::shutdown_both, ec);
        }
        socket_.close(ec);
        if (auto s = server_.lock()) {
            if (!s->stopped) s->protocol->units().client_gone(client_.id);
            s->log(spdlog::level::info, LogCause::Disconnected, "{}: {} disconnected ({})",
                   s->options.log_name, peer_, why);
            if (s->connections.erase(shared_from_this()) > 0 && s->options.room != nullptr)
                --s->options.room->open;
        }
    }

    /// The client sent its end while an answer of its was held.
    bool peer_done() const { return peer_done_; }
    /// When the last complete request arrived (the connect, before the first one).
    Clock::time_point last_request() const { return last_request_; }
    /// When the last request arrived or bytes were pushed to the client (a stream's events).
    Clock::time_point last_traffic() const { return std::max(last_request_, last_traffic_); }
    /// How long a begun request has been waiting for its last bytes (zero when none is).
    Clock::duration partial_for(Clock::time_point now) const {
        // While an answer is held (a delay fault) the client is not read: not its fault either.
        if (holding_) return Clock::duration{0};
        return frame_started_ == Clock::time_point{} ? Clock::duration{0} : now - frame_started_;
    }
    /// How long the client has sent no request since it connected (zero once it has). Bytes
    /// the protocol drops before a frame (noise, HTTP's blank lines) are none: a byte of them
    /// kept a connection from giving way; a frame begun is `partial_for`'s.
    Clock::duration mute_for(Clock::time_point now) const {
        return heard_ ? Clock::duration{0} : now - last_request_;
    }
    /// How long replies have been waiting for the client to take them (zero when none are).
    Clock::duration unsent_for(Clock::time_point now) const {
        return write_started_ == Clock::time_point{} ? Clock::duration{0} : now - write_started_;
    }
    /// The peer's address ("unspecified" when it could not be read).
    asio::ip::address address() const {
        asio::error_code ec;
        const auto ep = socket_.remote_endpoint(ec);
        return ec ? asio::ip::address() : ep.address();
    }

private:
    void read() {
        if (closed_) return;
        // Asio tries a queued read at once (a recv) unless the last one read nothing: when the
        // client has not sent its next request yet, that recv fails with EAGAIN and the read
        // waits for epoll (about one request in seven under a 16-connection load). The other
        // ways cost more: a wait-then-recv makes an epoll_ctl per request, and deferring the
        // read behind the other ready handlers saved the EAGAINs but no throughput
        // (docs/performance.md, "Servers compared in alternating rounds").
        if (reading_ || close_after_write_) return;
        // The client sent its end while an answer was held: what it sent is answered first.
        if (peer_done_) {
            if (!holding_) close("closed by peer");
            return;
        }
        if (holding_) {
            read_behind_hold();
            return;
        }
        if (used_ == buf_.size()) {
            // A protocol says Bad once its largest frame's bytes hold no frame (protocol.hpp):
            // a read into no room would complete at once, again and again.
            close("sent more than a frame holds");
            return;
        }
        reading_ = true;
        socket_.async_read_some(
            asio::buffer(buf_.data() + used_, buf_.size() - used_),
            [self = shared_from_this()](const asio::error_code& ec, std::size_t n) {
                self->reading_ = false;
                if (ec) {
                    self->close(ec == asio::error::eof ? "closed by peer" : "read error");
                    return;
                }
                self->used_ += n;
                // Filled: the client has more to say than the buffer holds.
                if (self->used_ == self->buf_.size()) {
                    self->buf_.resize(std::max(self->buf_.size(), full_buffer(self->max_frame_)));
                }
                self->serve();
            });
    }

    // Behind a held answer the client is read to notice it leave; what it sends is served after
    // the answer. The read goes to a buffer of its own: it may still be under way when the
    // answer has gone and the frames behind it are served, which moves the bytes in buf_.
    void read_behind_hold() {
        const std::size_t room = full_buffer(max_frame_) - used_;
        if (room == 0) return;  // full: read again once the answer has gone
        if (side_.empty()) side_.resize(kFirstBuffer);
        reading_ = true;
        socket_.async_read_some(
            asio::buffer(side_.data(), std::min(side_.size(), room)),
            [self = shared_from_this()](const asio::error_code& ec, std::size_t n) {
                self->reading_ = false;
                // The client's end may be a half-close that still waits for its answers, or a
                // close: kept until the answers are sent, but the first to give up its place to
                // a new client (evict_one).
                if (ec == asio::error::eof) {
                    self->peer_done_ = true;
                    if (!self->holding_ && !self->writing_) self->next();
                    return;
                }
                if (ec) {
                    self->close("read error");
                    return;
                }
                // used_ only fell since the read began (frames served): the bytes fit.
                if (self->used_ + n > self->buf_.size()) {
                    self->buf_.resize(full_buffer(self->max_frame_));
                }
                std::memcpy(self->buf_.data() + self->used_, self->side_.data(), n);
                self->used_ += n;
                if (self->holding_) {
                    self->read();
                    return;
                }
                self->serve();
            });
    }

    // Serves up to kFramesPerTurn complete frames (fewer once their replies reach
    // kBytesPerTurn), then writes their replies.
    void serve() {
        auto server = server_.lock();
        if (!server || closed_) return;
        // Nothing is served while a write is under way (its buffer must not move, and a client
        // that does not take its replies is not served more) or an answer is held (what came
        // behind it waits, in order): their ends serve what came (next). A read behind a hold
        // may end just after the hold did and serve a frame that is held in turn, while the
        // hold's end has already posted a serve.
        if (writing_ || holding_) return;
        std::size_t off = 0;
        std::size_t served = 0;
        const std::size_t queued = out_.size();
        while (served < kFramesPerTurn && out_.size() - queued < kBytesPerTurn) {
            const std::uint8_t* f = buf_.data() + off;
            const Split frame = session_ ? session_->split({f, used_ - off})
                                         : server->protocol->split({f, used_ - off});
            if (frame.cut == Cut::Incomplete) {
                if (session_) session_->waiting(out_);
                break;
            }
            // Noise before a frame: dropped unanswered, and no request (the client stays idle).
            if (frame.cut == Cut::Skip) {
                if (frame.size == 0) break;  // nothing to drop: no frame yet either
                off += frame.size;
                continue;
            }
            // No frame boundary can be trusted after a bad header: the connection (and only this
            // one) is closed.
            if (frame.cut == Cut::Bad) {
                spdlog::debug("tcp: {} {}", peer_, frame.why);
                // The requests before it are answered first, as far as the socket takes them.
                asio::error_code ec;
                if (!out_.empty()) socket_.write_some(asio::buffer(out_), ec);
                close(frame.why);
                return;
            }
            if (session_) {
                serving_ = true;
                const bool keep = session_->answer({f, frame.size}, out_);
                serving_ = false;
                off += frame.size;
                ++served;
                if (!keep) {
                    close_after_write_ = true;
                    break;
                }
                continue;
            }
            UnitTable& units = server->protocol->units();
            units.set_serving(&client_);
            const std::size_t n = server->protocol->answer({f, frame.size}, reply_);
            units.set_serving(nullptr);
            const Fate fate = units.take_fate();
            off += frame.size;
            ++served;
            if (fate.delay.count() > 0) {
                // Held: later frames wait behind it (the client is read only to notice it leave).
                hold(fate, n);
                break;
            }
            out_.insert(out_.end(), reply_.begin(), reply_.begin() + static_cast<long>(n));
            if (fate.close != Fate::Close::No) {
                close_after_fault(fate);
                break;
            }
        }
        if (off > 0) {
            std::memmove(buf_.data(), buf_.data() + off, used_ - off);
            used_ -= off;
        }
        const auto now = Clock::now();
        if (served > 0) {
            last_request_ = now;
            heard_ = true;
        }
        // The frame deadline runs from the first byte of a request that is not whole yet.
        if (used_ == 0) {
            frame_started_ = {};
        } else if (served > 0 || frame_started_ == Clock::time_point{}) {
            frame_started_ = now;
        }
        write();
    }

    void write() {
        if (closed_) return;
        // A write already under way takes what was queued behind it when it ends.
        if (writing_) return;
        if (!out_.empty()) {
            asio::error_code ec;
            const std::size_t n = socket_.write_some(asio::buffer(out_), ec);
            if (ec && ec != asio::error::would_block && ec != asio::error::try_again) {
                close("write error");
                return;
            }
            out_.erase(out_.begin(), out_.begin() + static_cast<long>(n));
        }
        if (!out_.empty()) {
            // The client is not taking its replies: stop reading it until it has. The wait
            // costs nothing (the reactor waits for room) and a reset ends it at once.
            write_started_ = Clock::now();
            writing_ = true;
            asio::async_write(socket_, asio::buffer(out_),
                              [self = shared_from_this()](const asio::error_code& ec, std::size_t) {
                                  self->writing_ = false;
                                  if (ec) {
                                      self->close(ec == asio::error::operation_aborted
                                                      ? "closed"
                                                      : "write error");
                                      return;
                                  }
                                  self->out_.clear();
                                  self->out_.swap(self->pending_);
                                  self->write_started_ = {};
                                  if (!self->out_.empty()) {
                                      self->write();
                                      return;
                                  }
                                  if (self->close_after_write_) {
                                      self->close("closed after its answer");
                                      return;
                                  }
                                  // The client was not read while it did not read: its frame clock
                                  // restarts.
                                  if (self->frame_started_ != Clock::time_point{}) {
                                      self->frame_started_ = Clock::now();
                                  }
                                  self->next();
                              });
            return;
        }
        if (close_after_write_) {
            close("closed after its answer");
            return;
        }
        next();
    }

    // A communication fault closes the connection once what is queued is sent.
    void close_after_fault(const Fate& fate) {
        reset_ = fate.close == Fate::Close::Reset;
        close_after_write_ = true;
    }

    // Holds an answer of `n` bytes (in reply_) for the fate's delay, then sends it.
    void hold(const Fate& fate, std::size_t n) {
        holding_ = true;
        held_.assign(reply_.begin(), reply_.begin() + static_cast<long>(n));
        hold_.expires_after(fate.delay);
        hold_.async_wait([self = shared_from_this(), fate](const asio::error_code& ec) {
            if (ec || self->closed_) return;
            self->holding_ = false;
            // What the client sent meanwhile has its frame clock from now, as after a write
            // it did not take.
            if (self->used_ > 0) self->frame_started_ = Clock::now();
            std::vector<std::uint8_t>& to = self->writing_ ? self->pending_ : self->out_;
            to.insert(to.end(), self->held_.begin(), self->held_.end());
            if (fate.close != Fate::Close::No) self->close_after_fault(fate);
            if (self->writing_) return;  // the write under way takes it, then goes on
            self->write();
        });
    }

    void arm_tick() {
        ticks_.expires_after(tick_period_);
        ticks_.async_wait([self = shared_from_this()](const asio::error_code& ec) {
            if (ec || self->closed_ || !self->session_) return;
            self->session_->tick();
            if (!self->closed_ && self->tick_period_.count() > 0) self->arm_tick();
        });
    }

    // More whole frames buffered: the others get their turn first. Otherwise: read.
    void next() {
        auto server = server_.lock();
        if (!server || closed_) return;
        if (holding_) {
            if (!peer_done_) read();  // to notice the client leave while its answer is held
            return;
        }
        const std::span<const std::uint8_t> buffered{buf_.data(), used_};
        if ((session_ ? session_->split(buffered) : server->protocol->split(buffered)).cut !=
            Cut::Incomplete) {
            asio::post(socket_.get_executor(), [self = shared_from_this()] { self->serve(); });
            return;
        }
        read();
    }

    std::size_t max_frame_;  // the protocol's largest frame
    tcp::socket socket_;
    std::weak_ptr<TcpListener::State> server_;
    std::string peer_;
    Client client_;  // as the PLCs' traffic lists it
    std::vector<std::uint8_t> buf_;
    std::size_t used_ = 0;
    std::vector<std::uint8_t> reply_;    // where the protocol answers one frame
    std::vector<std::uint8_t> out_;      // replies not yet taken by the client
    std::vector<std::uint8_t> pending_;  // sent while out_ is being written
    Clock::time_point last_request_;
    Clock::time_point last_traffic_;  // bytes pushed outside answers (send)
    Clock::time_point frame_started_{};
    Clock::time_point write_started_{};
    std::unique_ptr<Session> session_;  // the protocol's, when it answers through sessions
    asio::steady_timer ticks_;
    std::chrono::milliseconds tick_period_{0};
    asio::steady_timer hold_;         // an answer held by a delay fault
    std::vector<std::uint8_t> held_;  // that answer
    bool holding_ = false;            // one is held: nothing else is served meanwhile
    bool peer_done_ = false;          // the client's end was read while one was held
    bool heard_ = false;              // a request of the client's was served (mute_for)
    std::vector<std::uint8_t> side_;  // what is read while one is held (read_behind_hold)
    bool reset_ = false;              // closed with RST (a disconnect fault's `reset`)
    bool closed_ = false;
    bool reading_ = false;            // a read is under way
    bool writing_ = false;            // an asynchronous write is under way
    bool serving_ = false;            // inside serve(): it writes when done
    bool close_after_write_ = false;  // close once what is queued is sent (session, fault)
};

void TcpListener::State::accept() {
    if (options.room != nullptr && options.room->full()) {
        // The descriptors left for clients are taken: wait as when accept() itself runs out.
        accept_failed(std::make_error_code(std::errc::too_many_files_open));
        return;
    }
    acceptor.async_accept([self = shared_from_this()](const asio::error_code& ec, tcp::socket s) {
        if (self->stopped) return;
        if (ec) {
            if (ec != asio::error::operation_aborted) self->accept_failed(ec);
            return;
        }
        const auto now = Clock::now();
        if (self->accept_failures > 0 && !self->accept_calming) {
            // Said once accepts have worked for a while; a failure before then goes on with
            // the same episode.
            self->accept_calming = true;
            self->accept_calmed_at = now;
            self->accept_calm.expires_after(kAcceptCalm);
            self->accept_calm.async_wait([self](const asio::error_code& cec) {
                if (cec || self->stopped || !self->accept_calming) return;
                self->accept_calming = false;
                spdlog::info("{}: accepting again after {} failed accepts in {} ms",
                             self->options.log_name, self->accept_failures,
                             std::chrono::duration_cast<std::chrono::milliseconds>(
                                 self->accept_calmed_at - self->accept_failing_since)
                                 .count());
                self->accept_failures = 0;
            });
        }
        asio::error_code pec;
        const auto ep = s.remote_endpoint(pec);
        const std::string peer = pec ? std::string("?") : peer_name(ep);
        if (self->options.comm_faults && self->protocol->units().refusing()) {
            // Accepted before the fault could close the acceptor: reset, and close it now.
            s.set_option(asio::socket_base::linger(true, 0), pec);
            s.close(pec);
            ++self->refused;
            self->follow_refusal();
            return;
        }
        bool allowed = self->options.net.allow.empty();
        for (const auto& c : self->options.net.allow)
            allowed = allowed || (!pec && contains(c, ep.address()));
        if (!allowed) {
            self->log(spdlog::level::warn, LogCause::RefusedNotAllowed,
                      "{}: {} refused: not in {}.allow", self->options.log_name, peer,
                      self->options.section);
            s.close(pec);
            ++self->refused;
        } else if (self->options.room != nullptr && self->options.room->full()) {
            // Accepted by an accept armed before another listener filled the room: refused as
            // at max_clients; the accept below then waits for room.
            self->log(spdlog::level::warn, LogCause::RefusedFull,
                      "{}: {} refused: the descriptors left for clients are taken",
                      self->options.log_name, peer);
            s.close(pec);
            ++self->refused;
        } else if (static_cast<int>(self->connections.size()) >= self->options.net.max_clients &&
                   !self->evict_one(now)) {
            self->log(spdlog::level::warn, LogCause::RefusedFull,
                      "{}: {} refused: {} clients already connected ({}.max_clients)",
                      self->options.log_name, peer, self->connections.size(),
                      self->options.section);
            s.close(pec);
            ++self->refused;
        } else {
            s.set_option(tcp::no_delay(true), pec);
            set_keepalive(s);
            self->log(spdlog::level::info, LogCause::Connected, "{}: {} connected",
                      self->options.log_name, peer);
            auto c = std::make_shared<Connection>(
                std::move(s), self, peer, self->protocol->max_frame(), self->options.protocol);
            self->connections.insert(c);
            if (self->options.room != nullptr) ++self->options.room->open;
            ++self->accepted;
            c->start(*self->protocol);
        }
        self->accept();
    });
}

void TcpListener::State::accept_failed(const asio::error_code& ec) {
    const int e = ec.value();
    if (e != EMFILE && e != ENFILE && e != ENOBUFS && e != ENOMEM) {
        // A peer that reset before it was accepted, and the like: nothing to wait for.
        spdlog::debug("{}: accept: {}", options.log_name, ec.message());
        accept();
        return;
    }
    // Out of descriptors or memory: the listener stays readable, so retrying at once would
    // spin. A stuck or silent connection gives its descriptor up first; then back off, and log
    // once per episode (the count comes when accepts work again). One that gave way frees a
    // descriptor now: the next accept comes at the first back-off, not a doubled one (clients
    // behind a queue of mute ones got in one a second).
    const bool freed = evict_one(Clock::now());
    if (accept_calming) {
        // Accepts had worked again, but not for long: the same episode.
        accept_calming = false;
        accept_calm.cancel();
    }
    if (accept_failures++ == 0) {
        accept_failing_since = Clock::now();
        accept_backoff = kAcceptBackoffFirst;
        spdlog::warn(
            "{}: accept failed: {}; pausing accepts until a descriptor is free (raise the "
            "descriptor limit, LimitNOFILE=, or lower {}.max_clients)",
            options.log_name, ec.message(), options.section);
    } else if (freed) {
        accept_backoff = kAcceptBackoffFirst;
    } else {
        accept_backoff = std::min<Clock::duration>(accept_backoff * 2, kAcceptBackoffMax);
    }
    accept_retry.expires_after(accept_backoff);
    accept_retry.async_wait([self = shared_from_this()](const asio::error_code& wec) {
        if (wec || self->stopped) return;
        self->accept();
    });
}

bool TcpListener::State::evict_one(Clock::time_point now) {
    // Only a connection whose client sent its end while an answer was held, is stuck
    // mid-request or on unsent replies, or is silent for long, gives up its slot: the first
    // kind first (most such clients left; one that half-closed loses its held answers), then
    // the one stuck longest, else the one silent longest.
    for (const auto& c : connections) {
        if (c->peer_done()) {
            c->close("evicted for a new client: it left while its answer was held");
            return true;
        }
    }
    // A client that has sent no request since it connected is as stuck as one that stopped
    // mid-request: 64 bare connects held every slot until silent for evict_silent (30 s).
    std::shared_ptr<Connection> victim;
    Clock::duration worst{0};
    bool mute = false;
    for (const auto& c : connections) {
        const auto stuck = std::max(c->partial_for(now), c->unsent_for(now));
        const auto silent = c->mute_for(now);
        if (std::max(stuck, silent) >= kEvictStuck && std::max(stuck, silent) > worst) {
            worst = std::max(stuck, silent);
            victim = c;
            mute = silent > stuck;
        }
    }
    if (victim) {
        victim->close(mute ? "evicted for a new client: no request since it connected"
                           : "evicted for a new client: stuck mid-request");
        return true;
    }
    // An event stream too: what it is sent is no request of its client's.
    for (const auto& c : connections) {
        const auto silent = now - c->last_request();
        if (silent >= options.evict_silent && silent > worst) {
            worst = silent;
            victim = c;
        }
    }
    if (!victim) return false;
    const auto ms = std::chrono::duration_cast<std::chrono::milliseconds>(options.evict_silent);
    // Appended piece by piece: GCC 12 at -O2 takes `"literal" + std::string&&` for an
    // overlapping copy (-Wrestrict, a false positive that -Werror would make fatal).
    std::string why = "evicted for a new client: no request for ";
    if (ms.count() % 1000 == 0) {
        why += std::to_string(ms.count() / 1000);
        why += " s";
    } else {
        why += std::to_string(ms.count());
        why += " ms";
    }
    victim->close(why.c_str());
    return true;
}

void TcpListener::State::check_connections() {
    const auto now = Clock::now();
    const auto frame_limit = std::chrono::milliseconds(options.net.frame_timeout_ms);
    std::vector<std::pair<std::shared_ptr<Connection>, std::string>> doomed;
    for (const auto& c : connections) {
        // While its replies wait, a client is not read: a partial request then is not its fault.
        if (c->unsent_for(now) > frame_limit) {
            doomed.emplace_back(
                c, "replies not taken within " + options.section + ".frame_timeout_ms");
        } else if (c->unsent_for(now) == Clock::duration{0} && c->partial_for(now) > frame_limit) {
            doomed.emplace_back(
                c, "request not completed within " + options.section + ".frame_timeout_ms");
        } else if (options.net.idle_timeout_s > 0 &&
                   now - c->last_traffic() > std::chrono::seconds(options.net.idle_timeout_s)) {
            doomed.emplace_back(c, "idle timeout");
        }
    }
    for (const auto& [c, why] : doomed) c->close(why.c_str());
    if (options.comm_faults) follow_refusal();
    limiter.flush_to_log(now, options.log_name + ": ");
}

bool TcpListener::State::open_acceptor(asio::error_code& ec) {
    acceptor.open(bound.protocol(), ec);
    if (!ec) acceptor.set_option(tcp::acceptor::reuse_address(true), ec);
    if (!ec) acceptor.bind(bound, ec);
    if (!ec) acceptor.listen(asio::socket_base::max_listen_connections, ec);
    if (!ec) bound = acceptor.local_endpoint(ec);
    if (ec) {
        asio::error_code ignored;
        acceptor.close(ignored);
        return false;
    }
    return true;
}

void TcpListener::State::follow_refusal() {
    if (stopped) return;
    const bool refuse = protocol->units().refusing();
    if (refuse == refusing) return;
    asio::error_code ec;
    if (refuse) {
        acceptor.close(ec);
        refusing = true;
        arm_sweep();  // from now on at the refusing period: the socket opens soon after
        spdlog::info(
            "{}: {}: refusing new connections (communication fault "
            "refuse_connections)",
            options.log_name, peer_name(bound));
        return;
    }
    if (!open_acceptor(ec)) {
        // Taken meanwhile by another process: tried again at every sweep, said once.
        if (!relisten_failed) {
            spdlog::warn("{}: {}: cannot listen again: {}; trying on", options.log_name,
                         peer_name(bound), ec.message());
        }
        relisten_failed = true;
        return;
    }
    refusing = false;
    relisten_failed = false;
    arm_sweep();  // back to the usual period
    spdlog::info("{}: {}: accepting connections again", options.log_name, peer_name(bound));
    accept();
}

void TcpListener::State::arm_sweep() {
    if (stopped) return;
    // Fine enough for the frame deadline; a few hundred checks a second cost nothing.
    // While refusing, often enough that the listener opens soon after the fault clears.
    const auto period = refusing ? Clock::duration(std::chrono::milliseconds(50))
                                 : std::clamp<Clock::duration>(
                                       std::chrono::milliseconds(options.net.frame_timeout_ms) / 4,
                                       std::chrono::milliseconds(50), std::chrono::seconds(1));
    sweep.expires_after(period);
    sweep.async_wait([self = shared_from_this()](const asio::error_code& ec) {
        if (ec || self->stopped) return;
        self->check_connections();
        self->arm_sweep();
    });
}

TcpListener::TcpListener(asio::io_context& io, StreamProtocol& protocol, TcpOptions options)
    : state_(std::make_shared<State>(io, protocol, std::move(options))) {
    // The error names the listener and its section: "bind: Address already in use" alone does
    // not say which ("cannot listen on fatek tcp 0.0.0.0:500 (fatek.tcp)").
    const TcpOptions& o = state_->options;
    std::string where =
        "cannot listen on " + o.log_name + " " + o.net.bind + ":" + std::to_string(o.net.port);
    if (!o.section.empty()) where += " (" + o.section + ")";
    asio::error_code ec;
    const auto addr = asio::ip::make_address(state_->options.net.bind, ec);
    if (ec) throw std::system_error(ec, where);
    state_->bound = tcp::endpoint(addr, state_->options.net.port);
    if (!state_->open_acceptor(ec)) throw std::system_error(ec, where);
    state_->accept();
    state_->arm_sweep();
}

TcpListener::~TcpListener() { stop(); }

std::uint16_t TcpListener::port() const { return state_->bound.port(); }

std::string TcpListener::endpoint() const { return peer_name(state_->bound); }

std::size_t TcpListener::connections() const { return state_->connections.size(); }

ConnectionFigures TcpListener::figures() const {
    return {std::string(state_->options.protocol), endpoint(), state_->connections.size(),
            state_->accepted, state_->refused};
}

void TcpListener::set_limits(const TcpOptions& o) {
    state_->options.net.max_clients = o.net.max_clients;
    state_->options.net.idle_timeout_s = o.net.idle_timeout_s;
    state_->options.net.frame_timeout_ms = o.net.frame_timeout_ms;
    state_->options.net.allow = o.net.allow;
    // A peer taken off the allow list loses its connection now, not at its next reconnect.
    if (state_->options.net.allow.empty()) return;
    std::vector<std::shared_ptr<Connection>> refused;
    for (const auto& c : state_->connections) {
        bool ok = false;
        for (const auto& net : state_->options.net.allow) ok = ok || contains(net, c->address());
        if (!ok) refused.push_back(c);
    }
    const std::string why = "no longer in " + state_->options.section + ".allow";
    for (const auto& c : refused) c->close(why.c_str());
}

void TcpListener::stop() {
    if (state_->stopped) return;
    state_->stopped = true;
    asio::error_code ec;
    state_->acceptor.close(ec);
    state_->sweep.cancel();
    state_->accept_retry.cancel();
    state_->accept_calm.cancel();
    auto conns = state_->connections;
    for (const auto& c : conns) c->close("server stopping");
    // What the limiter holds back is said now: no sweep comes after.
    state_->limiter.flush_to_log(Clock::now(), state_->options.log_name + ": ", true);
}

}  // namespace plcemu::listener
