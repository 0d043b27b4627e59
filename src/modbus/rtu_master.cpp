#include "rtu_master.hpp"

#include <spdlog/spdlog.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <system_error>

#include "log_limiter.hpp"
#include "rtu_frame.hpp"
#include "rtu_framer.hpp"
#include "rtu_reply.hpp"

namespace plcemu::modbus {

namespace {

using Clock = std::chrono::steady_clock;

// A device that comes and goes (a loose USB adapter) is logged as it goes and comes back once
// per cause every 2 s, the rest counted (LogLimiter), as the TCP master logs its slaves.
constexpr std::size_t kLogBurst = 1;
constexpr auto kLogWindow = std::chrono::seconds(2);

}  // namespace

struct RtuMasterState : std::enable_shared_from_this<RtuMasterState> {
    RtuMasterState(asio::io_context& io, RtuOptions o)
        : options(std::move(o)),
          line(io),
          deadline(io),
          quiet(io),
          frame_end(io),
          framer(RtuTiming::for_line(
              options.baud, options.parity, options.data_bits, options.stop_bits)) {}

    // Opens the device and starts reading; throws std::system_error.
    void open() {
        const int fd = open_serial_line(options);
        asio::error_code ec;
        line.assign(fd, ec);
        if (ec) {
            ::close(fd);
            throw std::system_error(ec, "rtu: " + options.device);
        }
        up = true;
        opened = true;
        open_failed = false;
        framer.clear();
        read();
    }

    void transact(std::uint8_t to,
                  std::span<const std::uint8_t> pdu,
                  std::chrono::milliseconds timeout,
                  MasterDone d) {
        if (stopped) return;
        cancel();
        active = true;
        station = to;
        done = std::move(d);
        limiter.flush_to_log(Clock::now(), log_prefix);
        next_size = write_rtu(to, pdu, next);
        // The deadline runs from the request, whatever the line is doing (VB manual FNC149:
        // D9129 is how long the slave may take to respond).
        deadline.expires_after(timeout);
        deadline.async_wait(
            [self = shared_from_this(), g = generation](const asio::error_code& ec) {
                if (ec || self->stopped || g != self->generation || !self->active) return;
                self->finish(MasterOutcome::TimedOut, {});
            });
        if (next_size == 0) return;  // no frame holds it: it goes unanswered
        if (!up && !reopen()) return;
        send_after_silence();
    }

    // A line that failed, or could not be opened at a reload, is opened (again) by its path when
    // a transfer needs it; a failure is logged once.
    bool reopen() {
        const bool again = opened;
        try {
            open();
        } catch (const std::system_error& e) {
            if (!open_failed) {
                spdlog::warn("mbus: {}; trying again at every transfer", e.what());
                open_failed = true;
            }
            return false;
        }
        if (limiter.allow(LogCause::Connected, Clock::now()))
            spdlog::info("mbus: rtu {}: {}", options.device, again ? "reopened" : "opened");
        return true;
    }

    // Modbus over serial line 2.5.1.1: a frame starts after at least t3.5 of silence, counted
    // from the last byte either way. A line that never falls silent sends nothing: time-out.
    void send_after_silence() {
        const Clock::time_point at = quiet_from + framer.timing().t35;
        if (Clock::now() >= at) {
            send();
            return;
        }
        quiet.expires_at(at);
        quiet.async_wait([self = shared_from_this(), g = generation](const asio::error_code& ec) {
            if (ec || self->stopped || g != self->generation || !self->active) return;
            self->send_after_silence();
        });
    }

    // Writes the pending request unless a write is still under way (its end sends it) or the
    // line is down (the transaction times out).
    void send() {
        if (!up || writing || sent || !active) return;
        // What the line carried before the silence answers nothing.
        static_cast<void>(framer.expire(Clock::now()));
        tx = next;
        const std::size_t n = next_size;
        writing = true;
        asio::async_write(line, asio::buffer(tx.data(), n),
                          [self = shared_from_this(), e = epoch, g = generation, n](
                              const asio::error_code& ec, std::size_t) {
                              if (self->stopped || e != self->epoch) return;
                              self->writing = false;
                              if (ec) {
                                  self->lose(ec);
                                  return;
                              }
                              // The bytes are in the driver's buffer; the line carries them for
                              // this long.
                              self->quiet_from =
                                  std::max(self->quiet_from,
                                           Clock::now() + self->framer.timing().char_time *
                                                              static_cast<std::int64_t>(n));
                              if (g != self->generation || !self->active) {
                                  // That transaction ended while its frame went out; the next one
                                  // may wait.
                                  if (self->active) self->send_after_silence();
                                  return;
                              }
                              self->sent = true;
                              // No station answers a broadcast.
                              if (self->station == 0) self->finish(MasterOutcome::Sent, {});
                          });
    }

    void read() {
        line.async_read_some(asio::buffer(rx), [self = shared_from_this(), e = epoch](
                                                   const asio::error_code& ec, std::size_t n) {
            if (self->stopped || e != self->epoch) return;
            if (ec) {
                self->lose(ec);
                return;
            }
            const auto now = Clock::now();
            self->quiet_from = std::max(self->quiet_from, now);
            if (auto f = self->framer.receive({self->rx.data(), n}, now)) self->judge(*f);
            self->arm();
            self->read();
        });
    }

    void arm() {
        const auto at = framer.deadline();
        if (!at) return;
        frame_end.expires_at(*at);
        frame_end.async_wait([self = shared_from_this()](const asio::error_code& ec) {
            // A wait overtaken by a newer deadline may still run: expire() checks the time.
            if (ec || self->stopped) return;
            if (auto f = self->framer.expire(Clock::now())) {
                self->judge(*f);
            } else {
                self->arm();
            }
        });
    }

    // A frame the silence ended: the reply when a request is out and waits for one; anything
    // else (a late reply to an abandoned request, noise before a request) is dropped.
    void judge(const RtuFrame& f) {
        if (!active || !sent || station == 0) {
            spdlog::debug("mbus: rtu {}: {}-byte frame outside a transaction dropped",
                          options.device, f.bytes.size());
            return;
        }
        const RtuReply r = rtu_reply(f, station);
        finish(r.outcome, r.pdu);
    }

    void finish(MasterOutcome outcome, std::span<const std::uint8_t> pdu) {
        MasterDone d = std::move(done);
        cancel();
        if (d) d(outcome, pdu);
    }

    void cancel() noexcept {
        active = false;
        sent = false;
        done = nullptr;
        ++generation;
        deadline.cancel();
        quiet.cancel();
    }

    // A read or write error (EIO, a hang-up): the descriptor would fail forever, so it is closed;
    // the transaction on it waits for its deadline (status 5).
    void lose(const asio::error_code& ec) {
        if (up && limiter.allow(LogCause::Disconnected, Clock::now())) {
            spdlog::warn("mbus: rtu {}: lost ({}); opened again at the next transfer",
                         options.device, ec.message());
        }
        close();
    }

    void close() noexcept {
        up = false;
        writing = false;
        ++epoch;
        framer.clear();
        frame_end.cancel();
        asio::error_code ignored;
        line.close(ignored);
    }

    void stop() noexcept {
        if (stopped) return;
        stopped = true;
        cancel();
        close();
    }

    std::string description() const { return "rtu " + describe(options); }

    RtuOptions options;
    asio::posix::stream_descriptor line;
    asio::steady_timer deadline;   // the transaction's time-out
    asio::steady_timer quiet;      // the silence before the request
    asio::steady_timer frame_end;  // the silence that ends a frame
    RtuFramer framer;
    std::array<std::uint8_t, RtuFramer::kMaxFrame> next{};  // the request to send
    std::size_t next_size = 0;
    std::array<std::uint8_t, RtuFramer::kMaxFrame> tx{};  // the request being written
    std::array<std::uint8_t, 512> rx{};
    Clock::time_point quiet_from{};  // the line is silent from then on, as far as we know
    bool up = false;                 // the device is open
    bool opened = false;             // it was open once
    bool open_failed = false;        // the last reopen failed (logged once)
    LogLimiter limiter{kLogBurst, kLogWindow};
    const std::string log_prefix = "mbus: rtu " + options.device + ": ";  // the summary lines'
    bool writing = false;                                                 // a write is under way
    bool active = false;  // a transaction waits for its outcome
    bool sent = false;    // its request went out
    std::uint8_t station = 0;
    unsigned generation = 0;  // tells the handlers of an earlier transaction from this one's
    unsigned epoch = 0;       // tells the handlers of a closed descriptor from the open one's
    MasterDone done;
    bool stopped = false;
};

RtuMaster::RtuMaster(asio::io_context& io, RtuOptions options, Open open)
    : SharedStateTransport(std::make_shared<RtuMasterState>(io, std::move(options))) {
    if (open == Open::Now) {
        state_->open();
    } else {
        state_->reopen();
    }
}

RtuMaster::~RtuMaster() = default;

}  // namespace plcemu::modbus
