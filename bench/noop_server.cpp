// The machine's ceiling for the load client: a Modbus TCP server that only frames requests and
// answers FC03 with zeros. The gap between it and plcemud is what plcemud's own work costs.
// One thread and epoll, like plcemud, so the comparison is between equals. With --fatek it
// speaks FATEK's protocol instead: every frame (STX..ETX) is answered as command 46 with zeros
// for the count of registers the request names, with a correct checksum, and nothing checked.

#include <arpa/inet.h>
#include <netinet/in.h>
#include <netinet/tcp.h>
#include <sys/epoll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <cerrno>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>
#include <unordered_map>
#include <vector>

namespace {

struct Client {
    std::vector<uint8_t> in;   // received bytes not yet framed
    std::vector<uint8_t> out;  // replies not yet accepted by the kernel
    size_t out_sent = 0;
    bool waiting_writable = false;
};

unsigned be16(const uint8_t* p) { return static_cast<unsigned>(p[0] << 8 | p[1]); }

// Appends the reply to one complete MBAP frame (header + unit + PDU of `length - 1` bytes).
void answer(const uint8_t* frame, size_t length, std::vector<uint8_t>& out) {
    const uint8_t fc = frame[7];
    const unsigned quantity = length >= 6 ? be16(frame + 10) : 0;
    uint8_t exception = 0;
    if (fc != 0x03) {
        exception = 0x01;
    } else if (quantity < 1 || quantity > 125) {
        exception = 0x03;
    }
    const size_t pdu = exception != 0 ? 2 : 2 + 2 * quantity;
    const size_t at = out.size();
    out.resize(at + 7 + pdu);  // value-initialised: the registers are already zero
    uint8_t* r = out.data() + at;
    r[0] = frame[0];
    r[1] = frame[1];
    r[4] = static_cast<uint8_t>((pdu + 1) >> 8);
    r[5] = static_cast<uint8_t>(pdu + 1);
    r[6] = frame[6];
    if (exception != 0) {
        r[7] = static_cast<uint8_t>(fc | 0x80);
        r[8] = exception;
    } else {
        r[7] = 0x03;
        r[8] = static_cast<uint8_t>(2 * quantity);
    }
}

// Appends the reply to one FATEK frame: "<STX>01460" + 4 zeros per register + checksum + ETX.
void answer_fatek(const uint8_t* frame, size_t length, std::vector<uint8_t>& out) {
    auto hex = [](uint8_t c) { return c <= '9' ? c - '0' : (c | 0x20) - 'a' + 10; };
    const unsigned count =
        length >= 7 ? static_cast<unsigned>(hex(frame[5]) << 4 | hex(frame[6])) & 0xFF : 0;
    const size_t at = out.size();
    out.insert(out.end(), {0x02, frame[1], frame[2], '4', '6', '0'});
    out.insert(out.end(), 4 * static_cast<size_t>(count), '0');
    unsigned sum = 0;
    for (size_t i = at; i < out.size(); ++i) sum += out[i];
    const char* digits = "0123456789ABCDEF";
    out.insert(out.end(), {static_cast<uint8_t>(digits[(sum >> 4) & 0xF]),
                           static_cast<uint8_t>(digits[sum & 0xF]), 0x03});
}

class Server {
public:
    Server(int port, bool fatek)
        : port_(port),
          fatek_(fatek) {}

    int run() {
        listener_ = ::socket(AF_INET, SOCK_STREAM | SOCK_NONBLOCK, 0);
        const int one = 1;
        ::setsockopt(listener_, SOL_SOCKET, SO_REUSEADDR, &one, sizeof one);
        sockaddr_in addr{};
        addr.sin_family = AF_INET;
        addr.sin_port = htons(static_cast<uint16_t>(port_));
        addr.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
        if (::bind(listener_, reinterpret_cast<sockaddr*>(&addr), sizeof addr) != 0 ||
            ::listen(listener_, 128) != 0) {
            std::fprintf(stderr, "noop_server: port %d: %s\n", port_, std::strerror(errno));
            return 1;
        }
        ep_ = ::epoll_create1(0);
        watch(listener_, EPOLL_CTL_ADD, EPOLLIN);

        epoll_event events[64];
        for (;;) {
            const int n = ::epoll_wait(ep_, events, 64, -1);
            for (int i = 0; i < n; ++i) {
                const int fd = events[i].data.fd;
                if (fd == listener_) {
                    accept_all();
                } else if (events[i].events & (EPOLLERR | EPOLLHUP)) {
                    drop(fd);
                } else {
                    if (events[i].events & EPOLLOUT) flush(fd);
                    if (events[i].events & EPOLLIN) on_readable(fd);
                }
            }
        }
    }

private:
    void watch(int fd, int op, uint32_t events) {
        epoll_event ev{};
        ev.events = events;
        ev.data.fd = fd;
        ::epoll_ctl(ep_, op, fd, &ev);
    }

    void accept_all() {
        for (;;) {
            const int fd = ::accept4(listener_, nullptr, nullptr, SOCK_NONBLOCK);
            if (fd < 0) return;
            const int one = 1;
            ::setsockopt(fd, IPPROTO_TCP, TCP_NODELAY, &one, sizeof one);
            clients_[fd] = Client{};
            watch(fd, EPOLL_CTL_ADD, EPOLLIN);
        }
    }

    void drop(int fd) {
        ::close(fd);  // closing also removes it from the epoll set
        clients_.erase(fd);
    }

    void on_readable(int fd) {
        auto it = clients_.find(fd);
        if (it == clients_.end()) return;
        Client& c = it->second;
        uint8_t buf[16384];
        const ssize_t n = ::recv(fd, buf, sizeof buf, 0);
        if (n < 0 && (errno == EAGAIN || errno == EINTR)) return;
        if (n <= 0) return drop(fd);
        c.in.insert(c.in.end(), buf, buf + n);

        // Answer every complete frame in the buffer; a partial one waits for the next read.
        size_t pos = 0;
        while (fatek_ && pos < c.in.size()) {
            const auto* f = c.in.data() + pos;
            const auto* end = static_cast<const uint8_t*>(std::memchr(f, 0x03, c.in.size() - pos));
            if (end == nullptr) break;
            const auto length = static_cast<size_t>(end - f) + 1;
            answer_fatek(f, length, c.out);
            pos += length;
        }
        while (!fatek_ && c.in.size() - pos >= 7) {
            const uint8_t* f = c.in.data() + pos;
            const size_t length = be16(f + 4);
            // As the Modbus TCP spec asks: a frame we cannot delimit ends the connection.
            if (be16(f + 2) != 0 || length < 2 || length > 254) return drop(fd);
            if (c.in.size() - pos < 6 + length) break;
            answer(f, length, c.out);
            pos += 6 + length;
        }
        c.in.erase(c.in.begin(), c.in.begin() + static_cast<std::ptrdiff_t>(pos));
        flush(fd);
    }

    void flush(int fd) {
        auto it = clients_.find(fd);
        if (it == clients_.end()) return;
        Client& c = it->second;
        while (c.out_sent < c.out.size()) {
            const ssize_t n =
                ::send(fd, c.out.data() + c.out_sent, c.out.size() - c.out_sent, MSG_NOSIGNAL);
            if (n < 0 && errno == EAGAIN) {
                // Kernel buffer full: resume when writable instead of spinning.
                if (!c.waiting_writable) watch(fd, EPOLL_CTL_MOD, EPOLLIN | EPOLLOUT);
                c.waiting_writable = true;
                return;
            }
            if (n < 0) return drop(fd);
            c.out_sent += static_cast<size_t>(n);
        }
        c.out.clear();
        c.out_sent = 0;
        // Only touch the epoll set when it changes: the common path costs one send per read.
        if (c.waiting_writable) watch(fd, EPOLL_CTL_MOD, EPOLLIN);
        c.waiting_writable = false;
    }

    int port_;
    bool fatek_;
    int listener_ = -1;
    int ep_ = -1;
    std::unordered_map<int, Client> clients_;
};

}  // namespace

int main(int argc, char** argv) {
    const bool fatek = argc == 4 && std::string(argv[3]) == "--fatek";
    if ((argc != 3 && !fatek) || std::string(argv[1]) != "--port") {
        std::fprintf(stderr, "usage: %s --port N [--fatek]\n", argv[0]);
        return 2;
    }
    return Server(std::atoi(argv[2]), fatek).run();
}
