#include "listeners.hpp"

#include <spdlog/spdlog.h>

#include <algorithm>
#include <utility>

#include "daemon/fd_limit.hpp"
#include "daemon/protocols.hpp"
#include "plcemu/config/listener_key.hpp"

namespace plcemu::daemon {

listener::TcpOptions tcp_options(const config::Config& c) {
    listener::TcpOptions o;
    o.bind = c.modbus.tcp.bind;
    o.port = c.modbus.tcp.port;
    o.max_clients = c.modbus.tcp.max_clients;
    o.idle_timeout_s = c.modbus.tcp.idle_timeout_s;
    o.frame_timeout_ms = c.modbus.tcp.frame_timeout_ms;
    for (const auto& a : c.modbus.tcp.allow) {
        listener::Cidr cidr;
        if (!listener::Cidr::parse(a, cidr)) {
            throw config::ConfigError({c.path, 0, 0},
                                      "modbus.tcp.allow: bad CIDR '" + config::excerpt(a) + "'");
        }
        o.allow.push_back(cidr);
    }
    return o;
}

namespace {

// Descriptors a PLC needs besides its clients: its state file, a serial line, a master port.
constexpr int kPerPlc = 4;

// What a PLC listens on: "ADDR:PORT" (each PLC on port 0 gets a port of its own), the serial
// device, both as the config loader compares them; empty for none. PLCs with one key share that
// listener (the loader made sure they agree on its settings).
std::string tcp_key(const config::Config& c, std::size_t index) {
    if (!c.modbus.tcp.enabled) return {};
    if (c.modbus.tcp.port == 0) return "#" + std::to_string(index);
    return config::tcp_listener_key(c.modbus.tcp);
}

std::string rtu_key(const config::Config& c, std::size_t) {
    return c.modbus.rtu ? config::serial_line_key(c.modbus.rtu->device) : std::string();
}

struct Group {
    std::string key;
    std::vector<std::size_t> members;
};

template <typename Config, typename Key>
std::vector<Group> group(const std::vector<Config>& plcs, Key key) {
    std::vector<Group> out;
    for (std::size_t i = 0; i < plcs.size(); ++i) {
        const std::string k = key(plcs[i], i);
        if (k.empty()) continue;
        auto it = std::find_if(out.begin(), out.end(), [&](const Group& g) { return g.key == k; });
        if (it == out.end()) {
            out.push_back({k, {i}});
        } else {
            it->members.push_back(i);
        }
    }
    return out;
}

std::vector<std::size_t> members_with(const std::vector<Group>& groups, std::size_t plc) {
    for (const auto& g : groups) {
        if (std::find(g.members.begin(), g.members.end(), plc) != g.members.end()) return g.members;
    }
    return {};
}

listener::UnknownUnit policy(const config::Config& c) {
    return c.modbus.tcp.unknown_unit == config::UnknownUnit::Silent ? listener::UnknownUnit::Silent
                                                                    : listener::UnknownUnit::Refuse;
}

// The protocols today's config sections name: `modbus.tcp` and `modbus.rtu`.
constexpr std::string_view kTcpProtocol = "modbus-tcp";
constexpr std::string_view kSerialProtocol = "modbus-rtu";

std::vector<listener::Seat> seats(const std::vector<std::size_t>& members,
                                  const std::vector<ListenerMember>& plcs) {
    std::vector<listener::Seat> v;
    v.reserve(members.size());
    for (std::size_t i : members) v.push_back(plcs[i].seat);
    return v;
}

// A TCP listener's protocol, with no PLCs yet (route() seats them).
std::unique_ptr<listener::StreamProtocol> stream_protocol(std::string_view name) {
    return protocol(name).stream({});
}

}  // namespace

struct Listeners::Tcp {
    std::string key;
    std::vector<std::size_t> members;
    listener::TcpOptions options;
    // What it speaks; the server holds it, so it outlives the server.
    std::unique_ptr<listener::StreamProtocol> protocol = stream_protocol(kTcpProtocol);
    std::unique_ptr<listener::TcpListener> server;
};

struct Listeners::Rtu {
    std::string key;
    std::vector<std::size_t> members;
    std::unique_ptr<listener::SerialProtocol> protocol;
    std::unique_ptr<listener::SerialListener> server;
};

struct Listeners::Staged {
    std::size_t kept = 0;        // index into tcp_ when `fresh` is null
    std::unique_ptr<Tcp> fresh;  // a new listener
};

Listeners::Listeners(asio::io_context& io)
    : io_(io) {}

Listeners::~Listeners() { stop(); }

namespace {

// "plcs[0] (a), plcs[1]" for a shared listener's log line.
std::string names(const std::vector<std::size_t>& members,
                  const std::vector<ListenerMember>& plcs) {
    std::string s;
    for (std::size_t i : members) s += (s.empty() ? "" : ", ") + plcs[i].config->label;
    return s;
}

// "listening on tcp ADDR:PORT", after the PLC's label, or naming the PLCs that share it.
void log_listening(const std::string& what,
                   const std::string& where,
                   const std::vector<std::size_t>& members,
                   const std::vector<ListenerMember>& plcs) {
    if (members.size() == 1) {
        const std::string& label = plcs[members.front()].config->label;
        spdlog::info("{}listening on {} {}", label.empty() ? "" : label + ": ", what, where);
    } else {
        spdlog::info("listening on {} {} for {}", what, where, names(members, plcs));
    }
}

}  // namespace

void Listeners::open(const std::vector<ListenerMember>& plcs) {
    plcs_ = plcs;
    for (auto& g :
         group(plcs, [](const ListenerMember&m, std::size_t i) { return tcp_key(*m.config, i); })) {
        auto t = std::make_unique<Tcp>();
        t->key = std::move(g.key);
        t->members = std::move(g.members);
        t->options = tcp_options(*plcs[t->members.front()].config);
        t->server = std::make_unique<listener::TcpListener>(io_, *t->protocol, t->options);
        tcp_.push_back(std::move(t));
    }
    route(plcs);
    raise_fd_limit(plcs.size());
    for (const auto& t : tcp_) log_listening("tcp", t->server->endpoint(), t->members, plcs_);
    open_rtu(plcs, true);
}

void Listeners::open_rtu(const std::vector<ListenerMember>& plcs, bool at_start) {
    for (auto& g :
         group(plcs, [](const ListenerMember&m, std::size_t i) { return rtu_key(*m.config, i); })) {
        auto r = std::make_unique<Rtu>();
        r->key = std::move(g.key);
        r->members = std::move(g.members);
        const config::RtuConfig& c = *plcs[r->members.front()].config->modbus.rtu;
        r->protocol = protocol(kSerialProtocol)
                          .serial({seats(r->members, plcs),
                                   listener::UnknownUnit::Silent,
                                   {c.device, c.baud, c.parity, c.data_bits, c.stop_bits}});
        const std::string& label = plcs_[r->members.front()].config->label;
        const std::string prefix = r->members.size() == 1 && !label.empty() ? label + ": " : "";
        try {
            r->server = std::make_unique<listener::SerialListener>(
                io_, *r->protocol,
                listener::LineSettings{c.device, c.baud, c.parity, c.data_bits, c.stop_bits},
                "rtu");
        } catch (const std::exception& e) {
            if (at_start) throw;
            // The line stays listed without a server: its PLCs keep their unit IDs there (a
            // station change is checked against them), and the next reload tries it again.
            // e.what() says "rtu: ..." already.
            spdlog::error("reload: {}{}; serving without the serial port{}", prefix, e.what(),
                          r->members.size() > 1 ? " for " + names(r->members, plcs_) : "");
            rtu_.push_back(std::move(r));
            continue;
        }
        log_listening("rtu", r->server->description(), r->members, plcs_);
        rtu_.push_back(std::move(r));
    }
}

void Listeners::route(const std::vector<ListenerMember>& plcs) {
    for (auto& t : tcp_) {
        t->protocol->units().assign(seats(t->members, plcs));
        t->protocol->units().set_unknown_unit(policy(*plcs[t->members.front()].config));
    }
}

void Listeners::raise_fd_limit(std::size_t plcs) const {
    if (tcp_.empty()) return;
    // One descriptor per client of every listener, and the few each further PLC holds.
    int clients = 0;
    for (const auto& t : tcp_) clients += t->options.max_clients;
    ensure_fd_limit(clients + kPerPlc * static_cast<int>(plcs - 1));
}

std::string Listeners::refusal(const std::vector<config::Config>& next) const {
    auto old_groups = [](const auto& list) {
        std::vector<Group> out;
        out.reserve(list.size());
        for (const auto& l : list) out.push_back({l->key, l->members});
        return out;
    };
    const std::vector<Group> tcp_before = old_groups(tcp_);
    const std::vector<Group> rtu_before = old_groups(rtu_);
    const std::vector<Group> tcp_after = group(next, tcp_key);
    const std::vector<Group> rtu_after = group(next, rtu_key);
    for (std::size_t i = 0; i < next.size(); ++i) {
        for (const auto& [before, after, what] :
             {std::tuple{&tcp_before, &tcp_after, "tcp listener"},
              std::tuple{&rtu_before, &rtu_after, "serial line"}}) {
            const auto was = members_with(*before, i);
            const auto now = members_with(*after, i);
            if ((was.size() > 1 || now.size() > 1) && was != now) {
                return next[i].label + ": the PLCs sharing its " + what +
                       " changed; restart plcemud to apply it";
            }
        }
    }
    return {};
}

bool Listeners::stage(const std::vector<config::Config>& next) {
    staged_.clear();
    stopped_for_stage_.clear();
    for (auto& g : group(next, tcp_key)) {
        // The running listener of the same PLCs, if any (refusal() made sure the members are
        // the same ones when shared).
        const std::size_t first = g.members.front();
        auto running = std::find_if(tcp_.begin(), tcp_.end(), [&](const auto& t) {
            return std::find(t->members.begin(), t->members.end(), first) != t->members.end();
        });
        Staged s;
        if (running != tcp_.end() && (*running)->key == g.key) {
            s.kept = static_cast<std::size_t>(running - tcp_.begin());
            staged_.push_back(std::move(s));
            continue;
        }
        s.fresh = std::make_unique<Tcp>();
        s.fresh->key = g.key;
        s.fresh->members = g.members;
        s.fresh->options = tcp_options(next[first]);
        const std::string& label = next[first].label;
        const std::string prefix = label.empty() ? "" : label + ": ";
        try {
            s.fresh->server =
                std::make_unique<listener::TcpListener>(io_, *s.fresh->protocol, s.fresh->options);
            staged_.push_back(std::move(s));
            continue;
        } catch (const std::exception& e) {
            // e.what() names the endpoint ("cannot listen on tcp ADDR:PORT: ...").
            if (running == tcp_.end() || s.fresh->options.port == 0 ||
                s.fresh->options.port != (*running)->options.port || !(*running)->server) {
                spdlog::error("reload: {}{}", prefix, e.what());
                unstage();
                return false;
            }
        }
        // Same port, new address (127.0.0.1 -> 0.0.0.0): the old listener holds the port, so it
        // goes first; if the new one still fails, the old one comes back.
        spdlog::info("reload: {}closing tcp {} to listen on {}:{}", prefix,
                     (*running)->server->endpoint(), s.fresh->options.bind, s.fresh->options.port);
        (*running)->server->stop();
        (*running)->server.reset();
        stopped_for_stage_.push_back(static_cast<std::size_t>(running - tcp_.begin()));
        try {
            s.fresh->server =
                std::make_unique<listener::TcpListener>(io_, *s.fresh->protocol, s.fresh->options);
            staged_.push_back(std::move(s));
        } catch (const std::exception& e) {
            spdlog::error("reload: {}{}", prefix, e.what());
            unstage();
            return false;
        }
    }
    return true;
}

void Listeners::unstage() {
    for (auto& s : staged_) {
        if (s.fresh && s.fresh->server) s.fresh->server->stop();
    }
    staged_.clear();
    // The previous listeners again, after a reload that had to close them failed.
    for (std::size_t i : stopped_for_stage_) {
        Tcp& t = *tcp_[i];
        try {
            t.server = std::make_unique<listener::TcpListener>(io_, *t.protocol, t.options);
        } catch (const std::exception& e) {
            spdlog::error("tcp: cannot listen on {} again: {}; serving no TCP there", t.key,
                          e.what());
        }
    }
    stopped_for_stage_.clear();
}

void Listeners::apply(const std::vector<ListenerMember>& plcs) {
    std::vector<std::unique_ptr<Tcp>> now;
    for (auto& s : staged_) {
        if (s.fresh) {
            now.push_back(std::move(s.fresh));
            log_listening("tcp", now.back()->server->endpoint(), now.back()->members, plcs_);
            continue;
        }
        auto kept = std::move(tcp_[s.kept]);
        kept->options = tcp_options(*plcs[kept->members.front()].config);
        if (kept->server) kept->server->set_limits(kept->options);
        now.push_back(std::move(kept));
    }
    staged_.clear();
    stopped_for_stage_.clear();
    for (auto& t : tcp_) {
        if (t && t->server) t->server->stop();  // not kept: its PLCs left it
    }
    tcp_ = std::move(now);
    plcs_ = plcs;
    route(plcs);
    raise_fd_limit(plcs.size());
    // Serial lines are reopened with their new settings (and a device that came back is tried).
    for (auto& r : rtu_) {
        if (r->server) r->server->stop();
    }
    rtu_.clear();
    open_rtu(plcs, false);
}

void Listeners::stop() {
    for (auto& t : tcp_) {
        if (t && t->server) t->server->stop();
    }
    for (auto& s : staged_) {
        if (s.fresh && s.fresh->server) s.fresh->server->stop();
    }
    for (auto& r : rtu_) {
        if (r->server) r->server->stop();
    }
}

std::string Listeners::holder(std::size_t index, std::uint8_t unit) const {
    auto in = [index](const auto& l) {
        return std::find(l->members.begin(), l->members.end(), index) != l->members.end();
    };
    auto check = [&](const auto& l, const std::string& where) -> std::string {
        for (std::size_t j : l->members) {
            const listener::Seat& d = plcs_[j].seat;
            const char* what = j != index && *d.station == unit ? " station on "
                               : d.simulator != nullptr && d.simulator_unit == unit
                                   ? " simulator unit on "
                                   : nullptr;
            if (what == nullptr) continue;
            std::string who = j == index ? "its own" : plcs_[j].config->label + "'s";
            who += what;
            who += where;
            return who;
        }
        return {};
    };
    for (const auto& t : tcp_) {
        if (!in(t)) continue;
        // A PLC on port 0 has a key of its own ("#3"): the port it got says more.
        const std::string where = "tcp " + (t->server ? t->server->endpoint() : t->key);
        if (auto who = check(t, where); !who.empty()) return who;
    }
    for (const auto& r : rtu_) {
        if (!in(r)) continue;
        if (auto who = check(r, "serial line " + r->key); !who.empty()) return who;
    }
    return {};
}

std::string Listeners::unit_clash(const std::vector<config::Config>& next,
                                  const std::vector<std::uint8_t>& stations) const {
    // "station 5 (in force: set through R4055, the config says 1)".
    auto station = [&](std::size_t i) {
        std::string s = "station " + std::to_string(stations[i]);
        if (stations[i] != next[i].station) {
            s += " (in force: set through R4055; the config says " +
                 std::to_string(next[i].station) + ")";
        }
        return s;
    };
    for (std::size_t i = 0; i < next.size(); ++i) {
        if (next[i].simulator.unit != 0 && next[i].simulator.unit == stations[i]) {
            return (next[i].label.empty() ? std::string("the PLC") : next[i].label) + ": its " +
                   station(i) + " is also its simulator.unit";
        }
    }
    for (const auto& [groups, what] : {std::pair{group(next, tcp_key), "tcp listener "},
                                       std::pair{group(next, rtu_key), "serial line "}}) {
        for (const auto& g : groups) {
            for (std::size_t a = 0; a < g.members.size(); ++a) {
                for (std::size_t b = 0; b < a; ++b) {
                    const std::size_t i = g.members[a];
                    const std::size_t j = g.members[b];
                    const std::string where = " on the shared " + std::string(what) + g.key;
                    if (stations[i] == stations[j]) {
                        return next[i].label + ": its " + station(i) + " is also " + next[j].label +
                               "'s " + station(j) + where;
                    }
                    for (const auto& [x, y] : {std::pair{i, j}, std::pair{j, i}}) {
                        if (next[y].simulator.unit == stations[x]) {
                            return next[x].label + ": its " + station(x) + " is also " +
                                   next[y].label + "'s simulator unit" + where;
                        }
                    }
                }
            }
        }
    }
    return {};
}

std::string Listeners::describe(std::size_t index) const {
    std::string s;
    auto has = [index](const auto& l) {
        return std::find(l->members.begin(), l->members.end(), index) != l->members.end();
    };
    for (const auto& t : tcp_) {
        if (has(t) && t->server) s += ", tcp " + t->server->endpoint();
    }
    for (const auto& r : rtu_) {
        if (has(r) && r->server) s += ", rtu " + r->server->description();
    }
    return s;
}

}  // namespace plcemu::daemon
