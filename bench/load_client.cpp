// Modbus TCP load generator. Each connection keeps at most one FC03 request in flight, so the
// figures measure the server's turnaround rather than queueing in the client. Closed loop by
// default (the next request leaves as the reply arrives); with --interval-ms each connection
// polls at that period instead, as a SCADA does, its phase spread evenly over the period, and
// with --ports N the connections go to N consecutive ports, one each (one client per PLC of a
// `plcs:` config). One thread and epoll, so the client itself stays cheap next to the server
// on a small machine.
//
// With --protocol fatek it sends FATEK's command 46 (read --quantity registers, at most 64,
// from R<address>) to station --unit instead, framed STX..ETX with its checksum.
//
// Prints one `name value unit` line per figure, names prefixed with --label.

#include <arpa/inet.h>
#include <fcntl.h>
#include <netinet/in.h>
#include <netinet/tcp.h>
#include <sys/epoll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>
#include <vector>

namespace {

using Clock = std::chrono::steady_clock;

// MBAP header (7) + function code + byte count + 125 registers is the largest FC03 reply; a
// FATEK reply to 64 registers is 265 bytes.
constexpr size_t kMaxFrame = 512;

struct Options {
    std::string host = "127.0.0.1";
    int port = 502;
    int connections = 1;
    double seconds = 5.0;
    double warmup = 1.0;
    int unit = 1;
    int address = 0;
    int quantity = 125;
    int ports = 1;           // connection i goes to port + i % ports
    double interval_ms = 0;  // 0: closed loop; else each connection's polling period
    bool fatek = false;      // --protocol fatek
    std::string label;
};

struct Connection {
    int fd = -1;
    uint16_t transaction = 0;
    Clock::time_point sent;
    Clock::time_point next;  // paced: when the next request is due
    bool waiting = false;    // a request is in flight
    uint8_t in[kMaxFrame] = {};
    size_t have = 0;
    uint64_t measured = 0;  // replies completed inside the measuring window
    bool alive = true;
};

struct Stats {
    std::vector<int64_t> latency_ns;
    uint64_t errors = 0;
    uint64_t overrun = 0;  // paced: a request came due while the last was still unanswered
};

[[noreturn]] void usage(const char* argv0) {
    std::fprintf(stderr,
                 "usage: %s --port N [--host 127.0.0.1] [--connections C] [--seconds S]\n"
                 "          [--warmup W] [--unit 1] [--address 0] [--quantity 125] [--label L]\n"
                 "          [--ports N] [--interval-ms MS] [--protocol modbus|fatek]\n",
                 argv0);
    std::exit(2);
}

Options parse(int argc, char** argv) {
    Options o;
    for (int i = 1; i < argc; ++i) {
        const std::string key = argv[i];
        if (i + 1 >= argc) usage(argv[0]);
        const char* value = argv[++i];
        char* end = nullptr;
        const double number = std::strtod(value, &end);
        const bool numeric = end != value && *end == '\0';
        if (key == "--host") {
            o.host = value;
        } else if (key == "--label") {
            o.label = value;
        } else if (key == "--protocol") {
            const std::string p = value;
            if (p != "modbus" && p != "fatek") usage(argv[0]);
            o.fatek = p == "fatek";
        } else if (!numeric) {
            usage(argv[0]);
        } else if (key == "--port") {
            o.port = static_cast<int>(number);
        } else if (key == "--connections") {
            o.connections = static_cast<int>(number);
        } else if (key == "--seconds") {
            o.seconds = number;
        } else if (key == "--warmup") {
            o.warmup = number;
        } else if (key == "--unit") {
            o.unit = static_cast<int>(number);
        } else if (key == "--address") {
            o.address = static_cast<int>(number);
        } else if (key == "--quantity") {
            o.quantity = static_cast<int>(number);
        } else if (key == "--ports") {
            o.ports = static_cast<int>(number);
        } else if (key == "--interval-ms") {
            o.interval_ms = number;
        } else {
            usage(argv[0]);
        }
    }
    if (o.connections < 1 || o.quantity < 1 || o.quantity > (o.fatek ? 64 : 125) ||
        o.seconds <= 0 || o.ports < 1 || o.interval_ms < 0) {
        usage(argv[0]);
    }
    if (o.label.empty()) o.label = "load.c" + std::to_string(o.connections);
    return o;
}

int connect_to(const Options& o, int port) {
    sockaddr_in addr{};
    addr.sin_family = AF_INET;
    addr.sin_port = htons(static_cast<uint16_t>(port));
    if (inet_pton(AF_INET, o.host.c_str(), &addr.sin_addr) != 1) {
        errno = EINVAL;
        return -1;
    }
    const int fd = ::socket(AF_INET, SOCK_STREAM, 0);
    if (fd < 0) return -1;
    // Connect blocking: it happens before measuring, and it keeps error handling to one place.
    if (::connect(fd, reinterpret_cast<sockaddr*>(&addr), sizeof addr) != 0) {
        const int saved = errno;
        ::close(fd);
        errno = saved;
        return -1;
    }
    const int one = 1;
    ::setsockopt(fd, IPPROTO_TCP, TCP_NODELAY, &one, sizeof one);
    ::fcntl(fd, F_SETFL, ::fcntl(fd, F_GETFL) | O_NONBLOCK);
    return fd;
}

void put16(uint8_t* p, unsigned v) {
    p[0] = static_cast<uint8_t>(v >> 8);
    p[1] = static_cast<uint8_t>(v);
}

// FATEK's command 46: STX, station, "46", count, start register, checksum (the low byte of the
// sum of every byte before it), ETX; every number in upper-case hex but the register's.
size_t fatek_request(const Options& o, char* out, size_t room) {
    int n = std::snprintf(out, room, "\x02%02X46%02XR%05d", o.unit & 0xFF, o.quantity, o.address);
    unsigned sum = 0;
    for (int i = 0; i < n; ++i) sum += static_cast<unsigned char>(out[i]);
    n += std::snprintf(out + n, room - static_cast<size_t>(n), "%02X\x03", sum & 0xFF);
    return static_cast<size_t>(n);
}

bool send_request(Connection& c, const Options& o) {
    if (o.fatek) {
        char frame[32];
        const size_t n = fatek_request(o, frame, sizeof frame);
        c.sent = Clock::now();
        c.waiting = true;
        return ::send(c.fd, frame, n, MSG_NOSIGNAL) == static_cast<ssize_t>(n);
    }
    ++c.transaction;
    // MBAP header (protocol 0, length 6 = unit + PDU), then FC03 address and quantity.
    uint8_t frame[12] = {0, 0, 0, 0, 0, 6, static_cast<uint8_t>(o.unit), 0x03};
    put16(frame, c.transaction);
    put16(frame + 8, static_cast<unsigned>(o.address));
    put16(frame + 10, static_cast<unsigned>(o.quantity));
    c.sent = Clock::now();
    c.waiting = true;
    // With one request in flight the send buffer is empty, so 12 bytes go out whole or the
    // connection is broken; no partial-write bookkeeping is needed.
    return ::send(c.fd, frame, sizeof frame, MSG_NOSIGNAL) == static_cast<ssize_t>(sizeof frame);
}

bool reply_ok(const Connection& c, const Options& o, const uint8_t* f, size_t len) {
    const auto be16 = [](const uint8_t* p) { return static_cast<unsigned>(p[0] << 8 | p[1]); };
    const auto bytes = static_cast<size_t>(2 * o.quantity);
    return len == 9 + bytes && be16(f) == c.transaction && be16(f + 2) == 0 &&
           f[6] == static_cast<uint8_t>(o.unit) && f[7] == 0x03 && f[8] == bytes;
}

// STX, station, "46", error "0", four hex digits a register, checksum, ETX.
bool fatek_reply_ok(const Options& o, const uint8_t* f, size_t len) {
    return len == 9 + 4 * static_cast<size_t>(o.quantity) && f[0] == 0x02 && f[3] == '4' &&
           f[4] == '6' && f[5] == '0' && f[len - 1] == 0x03;
}

void close_connection(Connection& c, Stats& stats) {
    ::close(c.fd);
    c.alive = false;
    ++stats.errors;
}

// Consumes whatever has arrived; on a complete reply records it and sends the next request.
void on_readable(Connection& c,
                 const Options& o,
                 Stats& stats,
                 Clock::time_point window_start,
                 Clock::time_point window_end) {
    const ssize_t n = ::recv(c.fd, c.in + c.have, kMaxFrame - c.have, 0);
    if (n < 0 && (errno == EAGAIN || errno == EINTR)) return;
    if (n <= 0) return close_connection(c, stats);
    c.have += static_cast<size_t>(n);

    while (c.have >= 6) {
        size_t frame = 0;
        if (o.fatek) {
            // A FATEK frame ends at its ETX: there is no length field.
            const auto* end = static_cast<const uint8_t*>(std::memchr(c.in, 0x03, c.have));
            if (end == nullptr) {
                if (c.have == kMaxFrame) return close_connection(c, stats);
                return;
            }
            frame = static_cast<size_t>(end - c.in) + 1;
        } else {
            const size_t length = static_cast<size_t>(c.in[4] << 8 | c.in[5]);
            // A length we cannot frame leaves no way to resynchronise the stream.
            if (length < 2 || 6 + length > kMaxFrame) return close_connection(c, stats);
            frame = 6 + length;
            if (c.have < frame) return;
        }

        const auto now = Clock::now();
        if (o.fatek ? !fatek_reply_ok(o, c.in, frame) : !reply_ok(c, o, c.in, frame)) {
            ++stats.errors;
        } else if (now >= window_start && now < window_end) {
            stats.latency_ns.push_back((now - c.sent) / std::chrono::nanoseconds(1));
            ++c.measured;
        }
        c.have -= frame;
        std::memmove(c.in, c.in + frame, c.have);
        c.waiting = false;
        if (o.interval_ms > 0) continue;  // paced: the next request leaves when it is due
        if (!send_request(c, o)) return close_connection(c, stats);
    }
}

// Paced: sends every request that has come due and returns when the next one will.
Clock::time_point send_due(std::vector<Connection>& conns,
                           const Options& o,
                           Stats& stats,
                           size_t& alive,
                           Clock::duration period) {
    const auto now = Clock::now();
    auto soonest = now + period;
    for (auto& c : conns) {
        if (!c.alive) continue;
        if (c.next <= now) {
            if (c.waiting) {
                ++stats.overrun;  // still unanswered: this poll is skipped, as a SCADA would
            } else if (!send_request(c, o)) {
                close_connection(c, stats);
                --alive;
                continue;
            }
            c.next += period;
            if (c.next <= now) c.next = now + period;  // after a stall, no burst of catch-up
        }
        soonest = std::min(soonest, c.next);
    }
    return soonest;
}

double percentile_us(const std::vector<int64_t>& sorted, double q) {
    if (sorted.empty()) return 0.0;
    const auto rank = static_cast<size_t>(std::ceil(q * static_cast<double>(sorted.size())));
    return static_cast<double>(sorted[std::clamp<size_t>(rank, 1, sorted.size()) - 1]) / 1000.0;
}

}  // namespace

int main(int argc, char** argv) {
    const Options o = parse(argc, argv);

    std::vector<Connection> conns(static_cast<size_t>(o.connections));
    for (size_t i = 0; i < conns.size(); ++i) {
        const int port = o.port + static_cast<int>(i % static_cast<size_t>(o.ports));
        conns[i].fd = connect_to(o, port);
        if (conns[i].fd < 0) {
            std::fprintf(stderr, "load_client: cannot connect to %s:%d: %s\n", o.host.c_str(), port,
                         std::strerror(errno));
            return 1;
        }
    }

    const int ep = ::epoll_create1(0);
    for (size_t i = 0; i < conns.size(); ++i) {
        epoll_event ev{};
        ev.events = EPOLLIN;
        ev.data.u64 = i;
        ::epoll_ctl(ep, EPOLL_CTL_ADD, conns[i].fd, &ev);
    }

    Stats stats;
    const auto start = Clock::now();
    const auto window_start = start + std::chrono::duration_cast<Clock::duration>(
                                          std::chrono::duration<double>(o.warmup));
    const auto window_end = window_start + std::chrono::duration_cast<Clock::duration>(
                                               std::chrono::duration<double>(o.seconds));
    // Sized for well beyond loopback rates so the vector never reallocates while measuring.
    stats.latency_ns.reserve(static_cast<size_t>(o.seconds * 400000.0));

    const auto period = std::chrono::duration_cast<Clock::duration>(
        std::chrono::duration<double, std::milli>(o.interval_ms));
    const bool paced = o.interval_ms > 0;
    size_t alive = conns.size();
    if (paced) {
        // Phases spread evenly over the period, as independent pollers drift apart.
        for (size_t i = 0; i < conns.size(); ++i) {
            conns[i].next =
                start + period * static_cast<int64_t>(i) / static_cast<int64_t>(conns.size());
        }
    } else {
        alive = 0;
        for (auto& c : conns) {
            if (send_request(c, o)) {
                ++alive;
            } else {
                close_connection(c, stats);
            }
        }
    }

    std::vector<epoll_event> events(conns.size());
    for (auto now = Clock::now(); now < window_end && alive > 0; now = Clock::now()) {
        auto until = window_end;
        if (paced) until = std::min(until, send_due(conns, o, stats, alive, period));
        const auto left = std::chrono::ceil<std::chrono::milliseconds>(until - Clock::now());
        const int n = ::epoll_wait(ep, events.data(), static_cast<int>(events.size()),
                                   static_cast<int>(std::max<int64_t>(left.count(), 0)));
        for (int i = 0; i < n; ++i) {
            Connection& c = conns[events[static_cast<size_t>(i)].data.u64];
            if (!c.alive) continue;
            on_readable(c, o, stats, window_start, window_end);
            if (!c.alive) --alive;
        }
    }

    auto& lat = stats.latency_ns;
    std::sort(lat.begin(), lat.end());
    uint64_t slowest = UINT64_MAX;
    uint64_t fastest = 0;
    for (const auto& c : conns) {
        slowest = std::min(slowest, c.measured);
        fastest = std::max(fastest, c.measured);
    }
    const double fairness =
        fastest == 0 ? 0.0 : static_cast<double>(slowest) / static_cast<double>(fastest);
    const char* l = o.label.c_str();
    std::printf("%s.rps %.0f req/s\n", l, static_cast<double>(lat.size()) / o.seconds);
    std::printf("%s.p50 %.1f us\n", l, percentile_us(lat, 0.50));
    std::printf("%s.p99 %.1f us\n", l, percentile_us(lat, 0.99));
    std::printf("%s.p999 %.1f us\n", l, percentile_us(lat, 0.999));
    std::printf("%s.max %.1f us\n", l, percentile_us(lat, 1.0));
    std::printf("%s.fairness %.2f ratio\n", l, fairness);
    std::printf("%s.errors %llu count\n", l, static_cast<unsigned long long>(stats.errors));
    if (paced) {
        std::printf("%s.overruns %llu count\n", l, static_cast<unsigned long long>(stats.overrun));
    }

    for (const auto& c : conns) {
        if (c.alive) ::close(c.fd);
    }
    ::close(ep);
    return 0;
}
