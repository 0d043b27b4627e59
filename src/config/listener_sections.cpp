#include "config/listener_sections.hpp"

#include <arpa/inet.h>

#include <algorithm>
#include <vector>

#include "plcemu/config/listener_key.hpp"
#include "plcemu/config/listeners.hpp"

namespace plcemu::config {

namespace {

// A numeric IPv4/IPv6 address, as the listener and the allow list take them.
bool valid_address(const std::string& a) {
    unsigned char buf[16];
    return ::inet_pton(AF_INET, a.c_str(), buf) == 1 || ::inet_pton(AF_INET6, a.c_str(), buf) == 1;
}

bool starts_with(const std::string& s, const char* prefix) { return s.rfind(prefix, 0) == 0; }

}  // namespace

void read_tcp(const Reader& r, const Node& n, TcpConfig& tcp, const std::string& what) {
    const bool modbus = starts_with(what, "modbus.");
    const bool udp = what.size() >= 4 && what.compare(what.size() - 4, 4, ".udp") == 0;
    std::vector<std::string> keys{"enabled",     "bind",           "port",
                                  "allow",       "unknown_unit",   "read_only",
                                  "max_clients", "idle_timeout_s", "frame_timeout_ms"};
    // A unit-ID policy is Modbus's, `read_only` the other protocols' (Modbus has
    // modbus.read_only), and a UDP listener has no connections to limit.
    if (what == "http") keys.insert(keys.end(), {"token", "hosts"});
    std::erase_if(keys, [&](const std::string& k) {
        if (k == "unknown_unit") return !modbus;
        if (k == "read_only") return modbus;
        return udp && (k == "max_clients" || k == "idle_timeout_s" || k == "frame_timeout_ms");
    });
    r.check_keys(n, what, keys);
    r.attempt([&] {
        if (n["enabled"]) tcp.enabled = r.boolean(n["enabled"], what + ".enabled");
    });
    r.attempt([&] {
        if (n["bind"]) {
            tcp.bind = r.scalar(n["bind"], what + ".bind");
            if (!valid_address(tcp.bind)) {
                r.fail(n["bind"], what +
                                      ".bind: expected a numeric IPv4 or IPv6 address such as "
                                      "0.0.0.0 or ::, got '" +
                                      excerpt(tcp.bind) + "'");
            }
        }
    });
    r.attempt([&] {
        if (n["port"])
            tcp.port = static_cast<std::uint16_t>(r.integer(n["port"], what + ".port", 0, 65535));
    });
    r.attempt([&] {
        if (modbus && n["unknown_unit"]) {
            const std::string s = r.scalar(n["unknown_unit"], what + ".unknown_unit");
            if (s == "exception") {
                tcp.unknown_unit = UnknownUnit::Exception;
            } else if (s == "silent") {
                tcp.unknown_unit = UnknownUnit::Silent;
            } else {
                r.fail(n["unknown_unit"], what + ".unknown_unit: expected 'exception' or 'silent'");
            }
        }
    });
    r.attempt([&] {
        if (!modbus && n["read_only"])
            tcp.read_only = r.boolean(n["read_only"], what + ".read_only");
    });
    r.attempt([&] {
        if (const auto& a = n["allow"]) {
            if (!a.is_sequence()) r.fail(a, what + ".allow: expected a list of CIDR ranges");
            for (const auto& e : a.items) {
                r.attempt([&] {
                    const std::string written = r.scalar(e, what + ".allow entry");
                    auto cidr = Cidr::parse(written);
                    if (!cidr) {
                        r.fail(e, what +
                                      ".allow: expected a CIDR range such as 192.168.1.0/24 or an "
                                      "address, got '" +
                                      excerpt(written) + "'");
                    }
                    tcp.allow.push_back(std::move(*cidr));
                });
            }
        }
    });
    r.attempt([&] {
        if (what == "http" && n["token"]) {
            tcp.token = r.scalar(n["token"], what + ".token");
            // Sent in a header: printable ASCII without spaces (RFC 6750's token68 and more).
            const bool printable = std::all_of(tcp.token.begin(), tcp.token.end(),
                                               [](char ch) { return ch > ' ' && ch < 127; });
            if (tcp.token.empty() || tcp.token.size() > 256 || !printable) {
                r.fail(n["token"], what +
                                       ".token: expected 1 to 256 printable ASCII characters "
                                       "without spaces");
            }
        }
    });
    r.attempt([&] {
        const Node& h = n["hosts"];
        if (what != "http" || !h) return;
        if (!h.is_sequence()) r.fail(h, what + ".hosts: expected a list of host names");
        for (const auto& e : h.items) {
            r.attempt([&] {
                std::string name = r.scalar(e, what + ".hosts entry");
                const bool ok = !name.empty() && name.size() <= 253 &&
                                name.find_first_not_of(
                                    "abcdefghijklmnopqrstuvwxyz"
                                    "ABCDEFGHIJKLMNOPQRSTUVWXYZ0123456789.-") == std::string::npos;
                if (!ok) {
                    r.fail(e, what + ".hosts: expected a host name such as gateway.example, got '" +
                                  excerpt(name) + "'");
                }
                tcp.hosts.push_back(std::move(name));
            });
        }
    });
    if (udp) return;
    r.attempt([&] {
        if (n["max_clients"]) {
            tcp.max_clients =
                static_cast<int>(r.integer(n["max_clients"], what + ".max_clients", 1, 10000));
        }
    });
    r.attempt([&] {
        if (n["idle_timeout_s"]) {
            tcp.idle_timeout_s = static_cast<int>(
                r.integer(n["idle_timeout_s"], what + ".idle_timeout_s", 0, 86400));
        }
    });
    r.attempt([&] {
        if (n["frame_timeout_ms"]) {
            tcp.frame_timeout_ms = static_cast<int>(
                r.integer(n["frame_timeout_ms"], what + ".frame_timeout_ms", 100, 60000));
        }
    });
}

void read_fatek(const Reader& r, const Node& n, FatekConfig& fatek) {
    r.check_keys(n, "fatek", {"tcp", "udp", "serial"});
    // Port 500 is the FATEK Ethernet modules' (FBs-CBE/CM25E/CM55E), for TCP and UDP alike.
    constexpr std::uint16_t kFatekPort = 500;
    for (const auto& [key, slot] : {std::pair{"tcp", &fatek.tcp}, std::pair{"udp", &fatek.udp}}) {
        r.attempt([&, key = key, slot = slot] {
            const Node& s = n[key];
            if (!s || s.is_null()) return;
            TcpConfig t;
            t.port = kFatekPort;
            read_tcp(r, s, t, std::string("fatek.") + key);
            if (t.enabled) *slot = t;
        });
    }
    r.attempt([&] {
        const Node& s = n["serial"];
        if (!s || s.is_null()) return;
        // The FBs ports' character format: 9600 bps, 7 data bits, even parity, 1 stop bit.
        RtuConfig line;
        line.data_bits = 7;
        line.parity = 'E';
        read_line(r, s, line, "fatek.serial", true, true);
        fatek.serial = line;
    });
}

void read_http(const Reader& r, const Node& n, std::optional<TcpConfig>& http, bool on_anyway) {
    if (!n || n.is_null()) return;
    // The console can write: it listens on the loopback address unless told otherwise.
    constexpr std::uint16_t kHttpPort = 8020;
    TcpConfig t;
    t.bind = "127.0.0.1";
    t.port = kHttpPort;
    read_tcp(r, n, t, "http");
    // --http-port turns on a console the file turns off, with the file's token, read_only and
    // allow: never a console more open than the one written.
    if (on_anyway) t.enabled = true;
    if (t.enabled) http = t;
}

std::vector<ListenerConfig> listeners_of(const Config& c) {
    std::vector<ListenerConfig> v;
    if (c.modbus.tcp.enabled)
        v.push_back({"modbus-tcp", Carrier::Tcp, "modbus.tcp", &c.modbus.tcp});
    if (c.modbus.rtu) {
        v.push_back({"modbus-rtu", Carrier::Serial, "modbus.rtu", nullptr, &*c.modbus.rtu});
    }
    if (c.fatek.tcp) v.push_back({"fatek", Carrier::Tcp, "fatek.tcp", &*c.fatek.tcp});
    if (c.fatek.udp) v.push_back({"fatek", Carrier::Udp, "fatek.udp", &*c.fatek.udp});
    if (c.fatek.serial) {
        v.push_back({"fatek", Carrier::Serial, "fatek.serial", nullptr, &*c.fatek.serial});
    }
    if (c.http) v.push_back({"http", Carrier::Tcp, "http", &*c.http});
    return v;
}

std::string listener_key(const ListenerConfig& l) {
    switch (l.carrier) {
        case Carrier::Tcp:
            return "tcp " + tcp_listener_key(*l.net);
        case Carrier::Udp:
            return "udp " + tcp_listener_key(*l.net);
        case Carrier::Serial:
            break;
    }
    return "serial " + serial_line_key(l.line->device);
}

}  // namespace plcemu::config
