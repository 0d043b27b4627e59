#include "profiles/vb/mbus_config.hpp"

#include <arpa/inet.h>

#include <string>

#include "plcemu/profiles/profile.hpp"

namespace plcemu::profiles::vb {

namespace {

using config::Node;
using config::Reader;
using image::excerpt;

constexpr int kMaxStation = 247;

bool ip_address(const std::string& text) {
    unsigned char buf[16];
    return ::inet_pton(AF_INET, text.c_str(), buf) == 1 ||
           ::inet_pton(AF_INET6, text.c_str(), buf) == 1;
}

std::string host_of(const Reader& r, const Node& n, const std::string& what) {
    std::string host = r.scalar(n, what);
    // An address, not a name: resolving a name could block the event loop.
    if (!ip_address(host)) {
        r.fail(n, what + ": expected an IP address such as 127.0.0.1, got '" + excerpt(host) + "'");
    }
    return host;
}

std::uint16_t port_of(const Reader& r, const Node& n, const std::string& what) {
    return static_cast<std::uint16_t>(r.integer(n, what, 1, 65535));
}

config::TcpEndpoint tcp(const Reader& r, const Node& n) {
    r.check_keys(n, "mbus.tcp", {"host", "port"});
    if (!n["host"]) r.fail(n, "mbus.tcp: 'host' is required");
    config::TcpEndpoint e;
    e.host = host_of(r, n["host"], "mbus.tcp.host");
    e.port = n["port"] ? port_of(r, n["port"], "mbus.tcp.port") : 502;
    return e;
}

// `5: "127.0.0.1:5022"`, or `5: {host: 127.0.0.1, port: 5022}`; "[::1]:5022" for IPv6.
config::TcpEndpoint route(const Reader& r, const Node& n) {
    if (n.is_map()) {
        r.check_keys(n, "mbus.routes entry", {"host", "port"});
        if (!n["host"] || !n["port"])
            r.fail(n, "mbus.routes entry: 'host' and 'port' are required");
        return {host_of(r, n["host"], "mbus.routes.host"),
                port_of(r, n["port"], "mbus.routes.port")};
    }
    const std::string text = r.scalar(n, "mbus.routes entry");
    const auto colon = text.rfind(':');
    if (colon == std::string::npos) {
        r.fail(n, "mbus.routes entry: expected \"HOST:PORT\" such as \"127.0.0.1:5022\", got '" +
                      excerpt(text) + "'");
    }
    std::string host = text.substr(0, colon);
    if (host.size() > 2 && host.front() == '[' && host.back() == ']')
        host = host.substr(1, host.size() - 2);
    Node h = n;
    h.text = host;
    Node p = n;
    p.text = text.substr(colon + 1);
    return {host_of(r, h, "mbus.routes host"), port_of(r, p, "mbus.routes port")};
}

bool has_mbus(const config::Config& c, config::Position& where) {
    for (const auto& ic : profiles::program_instructions(c)) {
        if (ic.mnemonic == "MBUS") {
            where = ic.pos;
            return true;
        }
    }
    return false;
}

}  // namespace

std::optional<config::MasterConfig> read_mbus(const config::Config& c, const Reader& r) {
    const Node* section = nullptr;
    for (const auto& [name, node] : c.sections) {
        if (name == "mbus") section = &node;
    }
    config::Position mbus_at;
    const bool used = has_mbus(c, mbus_at);
    if (section == nullptr || section->is_null()) {
        if (used) {
            throw config::ConfigError(
                mbus_at,
                "MBUS: the program polls slaves, but the config has no mbus: section "
                "saying where (mbus: {tcp: {host: 127.0.0.1, port: 502}})");
        }
        return std::nullopt;
    }
    const Node& n = *section;
    // Each key and each route on its own: an error in one is recorded and the others are still
    // read (docs/configuration.md, "Configuration").
    const std::size_t before = r.errors_found();
    r.check_keys(n, "mbus", {"transport", "tcp", "routes", "rtu"});
    config::MasterConfig m;
    r.attempt([&] {
        if (!n["transport"]) return;
        const std::string t = r.scalar(n["transport"], "mbus.transport");
        if (t == "rtu") {
            m.transport = config::MasterTransport::Rtu;
        } else if (t != "tcp") {
            r.fail(n["transport"], "mbus.transport: expected tcp or rtu, got '" + excerpt(t) + "'");
        }
    });
    r.attempt([&] {
        if (n["tcp"]) m.tcp = tcp(r, n["tcp"]);
    });
    r.attempt([&] {
        const Node& routes = n["routes"];
        if (!routes) return;
        if (!routes.is_map())
            r.fail(routes, "mbus.routes: expected a mapping such as {5: \"127.0.0.1:5022\"}");
        for (const auto& entry : routes.entries) {
            r.attempt([&] {
                const Node& key = entry.first;
                config::MasterRoute route;
                route.station = static_cast<std::uint8_t>(
                    r.integer(key, "mbus.routes station", 1, kMaxStation));
                for (const auto& earlier : m.routes) {
                    if (earlier.station == route.station)
                        r.fail(key, "mbus.routes: station " + key.text + " twice");
                }
                route.endpoint = vb::route(r, entry.second);
                m.routes.push_back(route);
            });
        }
    });
    r.attempt([&] {
        if (!n["rtu"]) return;
        config::RtuConfig rtu;
        config::read_rtu(r, n["rtu"], rtu, "mbus.rtu", false);
        // The CP2 is a port of its own: the loader refuses its line to every listener and
        // every other port, this PLC's and the others' (Settings::own_lines).
        m.rtu = rtu;
    });
    // What the transport needs, once the keys it needs read cleanly (a key in error is not
    // reported again as missing).
    if (r.errors_found() != before) return m;
    if (m.transport == config::MasterTransport::Tcp && !n["tcp"] && m.routes.empty()) {
        r.fail(n, "mbus: transport tcp needs tcp: {host: ..., port: ...} or routes:");
    }
    if (m.transport == config::MasterTransport::Rtu && !m.rtu) {
        r.fail(n, "mbus: transport rtu needs rtu: {device: ...}");
    }
    return m;
}

}  // namespace plcemu::profiles::vb
