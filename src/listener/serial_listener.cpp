#include "serial_listener.hpp"

#include <spdlog/spdlog.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <cerrno>
#include <chrono>
#include <deque>
#include <new>
#include <vector>
#include <system_error>
#include <utility>

#include "modbus/rtu_framer.hpp"
#include "modbus/serial_line.hpp"

namespace plcemu::listener {

namespace {

using Clock = std::chrono::steady_clock;

// A device that went away (USB adapter unplugged, socat restarted) is reopened by its path:
// first soon, then less and less often, so a port that stays gone costs nothing.
constexpr auto kFirstReopen = std::chrono::milliseconds(100);
constexpr auto kMaxReopen = std::chrono::seconds(5);
// A reopened device counts as back once it has delivered a byte or stayed readable this long: one
// that opens and fails at once is the same outage, not a new "reopened"/"lost" pair.
constexpr auto kSettle = std::chrono::seconds(1);
// Answers held at once by communication faults (a delay) before further ones are dropped.
constexpr std::size_t kMaxHeld = 64;
// With `echo: true`, how long after an answer has left the wire its echo may still begin: a USB
// adapter hands bytes over in batches (an FTDI chip every 16 ms by default).
constexpr auto kEchoWait = std::chrono::milliseconds(100);

}  // namespace

struct SerialListener::State : std::enable_shared_from_this<SerialListener::State> {
    State(asio::io_context& io,
          SerialProtocol& p,
          LineSettings o,
          std::string n,
          std::string_view protocol_name)
        : protocol(p),
          options(std::move(o)),
          name(std::move(n)),
          line(io),
          frame_end(io),
          reopen_timer(io),
          release(io),
          client(make_client(options.device, protocol_name, Carrier::Line)),
          timing(modbus::RtuTiming::for_line(
              options.baud, options.parity, options.data_bits, options.stop_bits)),
          echo_timer(io) {}

    void read() {
        if (stopped) return;
        line.async_read_some(asio::buffer(buf),
                             [self = shared_from_this()](const asio::error_code& ec,
                                                         std::size_t n) { self->on_read(ec, n); });
    }

    void on_read(const asio::error_code& ec, std::size_t n) {
        if (stopped || ec == asio::error::operation_aborted) return;
        if (ec) {
            lose(ec);
            return;
        }
        if (link == Link::Settling) back();  // a byte proves the reopened device
        const auto now = Clock::now();
        const std::span<const std::uint8_t> bytes = cancel_echo({buf.data(), n}, now);
        // The silence before these bytes may have ended the previous frame even if its timer
        // has not fired yet (the loop was busy): serve that frame first.
        if (!bytes.empty()) deliver(bytes, now);
        arm();
        read();
    }

    void deliver(std::span<const std::uint8_t> bytes, Clock::time_point at) {
        protocol.units().set_serving(&client);
        answer(protocol.receive(bytes, at));
        protocol.units().set_serving(nullptr);
    }

    // A line that echoes what is sent (an RS-485 adapter with local echo) hands every answer
    // back as if a master had sent it, and the answer to that is echoed in turn, for ever (a
    // write's reply is the write again). Neither the bytes nor their timing tell an echo from a
    // master on a pty or a USB adapter, so the line says it echoes (`echo: true`): after each
    // answer, bytes repeating it from its first byte on are its echo and are dropped. Bytes that
    // stop matching are read as they came, those held before them first; an echo that does not
    // begin within kEchoWait of the answer is no longer waited for. Returns what is left of `in`.
    std::span<const std::uint8_t> cancel_echo(std::span<const std::uint8_t> in,
                                              Clock::time_point now) {
        std::size_t k = 0;
        while (k < in.size() && echo_matched < echo.size()) {
            if (echo_matched == 0 && now > echo_until) break;  // too late to be the echo
            if (in[k] != echo[echo_matched]) {
                release_echo();
                return in.subspan(k);
            }
            echo_read_at[echo_matched++] = now;
            ++k;
        }
        // The whole echo came (dropped), or none began in time (no longer looked for); else
        // part of it came.
        if (echo_matched == echo.size() || echo_matched == 0 || k < in.size()) {
            echo.clear();
            echo_matched = 0;
        } else {
            // Part of it came: the rest is due within the line's time for it.
            echo_timer.expires_at(now + timing.t35 +
                                  timing.char_time * static_cast<long>(echo.size() - echo_matched));
            echo_timer.async_wait([self = shared_from_this()](const asio::error_code& ec) {
                if (ec || self->stopped || self->echo_matched == 0) return;
                self->release_echo();
                self->arm();
            });
        }
        return in.subspan(k);
    }

    // What was held as a possible echo was not one: the protocol reads it as it came.
    void release_echo() {
        echo_timer.cancel();
        if (echo_matched == 0) {
            echo.clear();
            return;
        }
        // Copied: an answer to them replaces `echo`.
        const std::vector<std::uint8_t> bytes(
            echo.begin(), echo.begin() + static_cast<std::ptrdiff_t>(echo_matched));
        const std::vector<Clock::time_point> at(
            echo_read_at.begin(), echo_read_at.begin() + static_cast<std::ptrdiff_t>(echo_matched));
        echo.clear();
        echo_matched = 0;
        // Each read's bytes at its own time, so the protocol times the silences between them.
        for (std::size_t i = 0; i < bytes.size();) {
            std::size_t j = i + 1;
            while (j < bytes.size() && at[j] == at[i]) ++j;
            deliver(std::span(bytes).subspan(i, j - i), at[i]);
            i = j;
        }
    }

    void arm() {
        const auto deadline = protocol.deadline();
        if (!deadline) return;
        frame_end.expires_at(*deadline);
        frame_end.async_wait([self = shared_from_this()](const asio::error_code& ec) {
            // A wait overtaken by a newer deadline may still run: expire() checks the time.
            if (ec || self->stopped) return;
            if (const auto d = self->protocol.deadline(); d && Clock::now() < *d) {
                self->arm();
                return;
            }
            self->protocol.units().set_serving(&self->client);
            self->answer(self->protocol.expire(Clock::now()));
            self->protocol.units().set_serving(nullptr);
        });
    }

    // An answer, with what its communication faults make of it: held for a delay, or sent in
    // two parts with a pause between (a garble). Answers go out in the order they were made.
    void answer(std::span<const std::uint8_t> a) {
        const Fate fate = protocol.units().take_fate();
        if (a.empty()) return;
        if (fate.delay.count() == 0 && fate.gap_at == 0 && held.empty()) {
            write(a);
            return;
        }
        // A master that floods a line whose answers are held gets no more held.
        // Every answer lost so is counted dropped by its PLC's faults, delayed or not.
        if (held.size() >= kMaxHeld) {
            if (fate.by != nullptr) fate.by->held_over(fate.delay.count() > 0);
            return;
        }
        const auto due = Clock::now() + fate.delay;
        try {
            if (fate.gap_at > 0 && fate.gap_at < a.size()) {
                held.push_back({due, {}, {a.begin(), a.begin() + static_cast<long>(fate.gap_at)}});
                held.push_back(
                    {{}, fate.gap, {a.begin() + static_cast<long>(fate.gap_at), a.end()}});
            } else {
                held.push_back({due, {}, {a.begin(), a.end()}});
            }
        } catch (const std::bad_alloc&) {
            // The answer is lost, as on a line that garbled it.
            if (fate.by != nullptr) fate.by->held_over(fate.delay.count() > 0);
            return;
        }
        send_held();
    }

    // Sends the held answers that are due, and waits for the next.
    void send_held() {
        while (!held.empty() && held.front().due <= Clock::now()) {
            write(held.front().bytes);
            held.pop_front();
            // The pause of a gap runs from the first part's going out.
            if (!held.empty() && held.front().after.count() > 0)
                held.front().due = Clock::now() + held.front().after;
        }
        if (held.empty()) return;
        release.expires_at(held.front().due);
        release.async_wait([self = shared_from_this()](const asio::error_code& ec) {
            if (ec || self->stopped) return;
            self->send_held();
        });
    }

    // The answer goes to the non-blocking descriptor, never waited for (no tcdrain): when the
    // tty's buffer is full (a master that floods the line and never reads it) the rest of the
    // answer is dropped. A tty does not say how much room it has, so the answer that fills it
    // may go out cut short: its CRC (or ETX) then fails at the master, as a line's noise does,
    // and the answers that follow, once there is room, are whole.
    void write(std::span<const std::uint8_t> answer) noexcept {
        if (answer.empty()) return;
        const ssize_t w = ::write(line.native_handle(), answer.data(), answer.size());
        if (!options.echo || w <= 0 || echo_matched > 0) return;
        // What its echo will be, and until when it may begin (see cancel_echo()).
        try {
            echo.assign(answer.begin(), answer.begin() + w);
            echo_read_at.resize(echo.size());
        } catch (const std::bad_alloc&) {
            echo.clear();
            return;
        }
        echo_until = Clock::now() + timing.char_time * w + kEchoWait;
    }

    // A read error (EIO or hang-up of a device that went away): re-reading the same descriptor
    // would fail forever, so close it and reopen the device by its path.
    void lose(const asio::error_code& ec) {
        const bool had_device = link != Link::Lost;
        if (link == Link::Up) {
            spdlog::warn("{}: {}: lost ({}); reopening with back-off", name, options.device,
                         ec.message());
            // One that fails again soon after coming back keeps the longer wait: no fast flapping.
            if (Clock::now() - opened_at >= kSettle) backoff = kFirstReopen;
        }
        // From Settling: the reopened device failed before proving itself; the back-off goes on.
        link = Link::Lost;
        protocol.clear();  // what came before the error is not a frame to answer
        held.clear();      // nor is there a line for held answers
        release.cancel();
        protocol.units().client_gone(client.id);  // the line's master is no longer heard
        frame_end.cancel();
        asio::error_code ignored;
        line.close(ignored);
        echo.clear();
        echo_matched = 0;
        echo_timer.cancel();
        reopen_later();
        if (had_device && on_device_change) on_device_change();
    }

    void reopen_later() {
        reopen_timer.expires_after(backoff);
        reopen_timer.async_wait([self = shared_from_this()](const asio::error_code& ec) {
            if (ec || self->stopped) return;
            self->reopen();
        });
    }

    void reopen() {
        // Whether this attempt fails or the device fails again right after it, wait longer.
        backoff = std::min<Clock::duration>(backoff * 2, kMaxReopen);
        int fd = -1;
        try {
            fd = modbus::open_serial_line(options, name);
        } catch (const std::system_error&) {
            reopen_later();  // still gone: silent, "lost" said it once
            return;
        }
        asio::error_code assigned;
        line.assign(fd, assigned);
        if (assigned) {
            ::close(fd);
            reopen_later();
            return;
        }
        link = Link::Settling;
        opened_at = Clock::now();
        const unsigned opened = ++opens;
        reopen_timer.expires_after(kSettle);
        reopen_timer.async_wait([self = shared_from_this(), opened](const asio::error_code& ec) {
            // A wait that already completed when the device was lost again may still run.
            if (ec || self->stopped || self->opens != opened) return;
            if (self->link == Link::Settling) self->back();
        });
        read();
        if (on_device_change) on_device_change();  // from Lost: the device is back
    }

    void back() {
        link = Link::Up;
        reopen_timer.cancel();
        spdlog::info("{}: {}: reopened", name, options.device);
    }

    SerialProtocol& protocol;
    LineSettings options;
    std::string name;  // "rtu", starts the log lines
    asio::posix::stream_descriptor line;
    asio::steady_timer frame_end;
    // Waits between attempts to reopen a lost device, then for it to settle.
    asio::steady_timer reopen_timer;
    // Answers held by communication faults, in order; `after`: a gap's pause behind the one
    // before, its due time set when that one goes out.
    struct Held {
        Clock::time_point due;
        std::chrono::microseconds after;
        std::vector<std::uint8_t> bytes;
    };
    std::deque<Held> held;
    asio::steady_timer release;
    std::array<std::uint8_t, 512> buf{};
    // Up: reading; Lost: closed, waiting to reopen; Settling: reopened, not yet proven.
    enum class Link { Up, Lost, Settling };
    Link link = Link::Up;
    Clock::duration backoff = kFirstReopen;
    Clock::time_point opened_at = Clock::now();
    unsigned opens = 0;  // tells a settle wait from the ones of earlier reopens
    bool stopped = false;
    // The line's master, as its PLCs list their clients: one per line, whoever it is.
    Client client;
    // Told when the device goes or comes back (the listeners' descriptions say which).
    std::function<void()> on_device_change;
    // The line's echo (cancel_echo(), with `echo: true`): the last answer written, how much of
    // it has been read back and when, and until when its echo may begin.
    modbus::RtuTiming timing;
    std::vector<std::uint8_t> echo;
    std::size_t echo_matched = 0;
    std::vector<Clock::time_point> echo_read_at;
    Clock::time_point echo_until{};
    asio::steady_timer echo_timer;
};

SerialListener::SerialListener(asio::io_context& io,
                               SerialProtocol& protocol,
                               LineSettings line,
                               std::string name,
                               std::string_view protocol_name,
                               bool wait_for_device)
    : state_(
          std::make_shared<State>(io, protocol, std::move(line), std::move(name), protocol_name)) {
    try {
        state_->line.assign(modbus::open_serial_line(state_->options, state_->name));
    } catch (const std::system_error& e) {
        if (!wait_for_device) throw;
        // As a device lost while open: tried again with back-off, "reopened" once it is back.
        absent_ = e.what();
        state_->link = State::Link::Lost;
        state_->reopen_later();
        return;
    }
    state_->read();
}

SerialListener::~SerialListener() { stop(); }

std::string SerialListener::description() const { return modbus::describe(state_->options); }

bool SerialListener::has_device() const noexcept { return state_->link != State::Link::Lost; }

void SerialListener::on_device_change(std::function<void()> f) {
    state_->on_device_change = std::move(f);
}

void SerialListener::stop() {
    if (state_->stopped) return;
    state_->stopped = true;
    state_->on_device_change = nullptr;
    spdlog::info("{}: {}: {}", state_->name, state_->options.device, state_->protocol.summary());
    asio::error_code ec;
    state_->frame_end.cancel();
    state_->reopen_timer.cancel();  // no reopen after stop
    state_->release.cancel();
    state_->echo_timer.cancel();
    state_->protocol.units().client_gone(state_->client.id);
    state_->line.cancel(ec);
    state_->line.close(ec);
}

}  // namespace plcemu::listener
