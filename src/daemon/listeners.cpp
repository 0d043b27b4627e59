#include "listeners.hpp"

#include <spdlog/spdlog.h>

#include <algorithm>
#include <array>
#include <map>
#include <stdexcept>
#include <string>
#include <system_error>
#include <unordered_map>
#include <utility>

#include "daemon/fd_limit.hpp"
#include "daemon/protocols.hpp"
#include "listener/serial_listener.hpp"
#include "listener/tcp_listener.hpp"
#include "listener/udp_listener.hpp"

namespace plcemu::daemon {

using config::Carrier;

namespace {

// Descriptors a PLC needs besides its clients: its state file, a serial line, a master port.
constexpr int kPerPlc = 4;

// The descriptors `plcs` PLCs need beside those a process keeps (kFdReserve): the clients of
// every TCP listener (its section and max_clients) together, and each further PLC's own; and
// what they are for, as the log says it, each section once in the order of their names
// ("http.max_clients 64, modbus.tcp.max_clients of 2 listeners (128 clients), and 4 more
// PLCs").
std::pair<int, std::string> descriptors_for(
    const std::vector<std::pair<std::string_view, int>>& listeners, std::size_t plcs) {
    struct Section {
        int clients = 0;
        std::size_t listeners = 0;
    };
    std::map<std::string_view, Section> sections;
    int clients = 0;
    for (const auto& [section, max_clients] : listeners) {
        clients += max_clients;
        Section& s = sections[section];
        s.clients += max_clients;
        ++s.listeners;
    }
    std::string what;
    for (const auto& [name, s] : sections) {
        if (!what.empty()) what += ", ";
        what += std::string(name) + ".max_clients ";
        what += s.listeners == 1 ? std::to_string(s.clients)
                                 : "of " + std::to_string(s.listeners) + " listeners (" +
                                       std::to_string(s.clients) + " clients)";
    }
    if (plcs > 1) what += ", and " + std::to_string(plcs - 1) + " more PLCs";
    return {clients + kPerPlc * static_cast<int>(plcs - 1), what};
}

// How logs and the status line name a listener's kind: "tcp" and "rtu" for Modbus (as always),
// "fatek tcp", "fatek udp", "fatek serial" for the others.
std::string kind_words(std::string_view protocol, Carrier carrier) {
    if (protocol == "modbus-tcp") return "tcp";
    if (protocol == "modbus-rtu") return "rtu";
    if (protocol == "http") return "http";
    const char* c = carrier == Carrier::Tcp ? "tcp" : carrier == Carrier::Udp ? "udp" : "serial";
    return std::string(protocol) + " " + c;
}

// A network listener's settings; its log lines begin with its kind ("tcp: 192.0.2.7:50312
// connected", "fatek tcp: ...").
listener::TcpOptions net_options(const config::ListenerConfig& l) {
    const config::TcpConfig& t = *l.net;
    listener::TcpOptions o;
    o.net = t;
    o.section = std::string(l.section);
    o.log_name = kind_words(l.protocol, l.carrier);
    // The console switches faults off: it never refuses.
    if (l.protocol == "http") o.comm_faults = false;
    o.protocol = l.protocol;
    return o;
}

// The listener of `section` in `c`, if it asks for one.
std::optional<config::ListenerConfig> listener_in(const config::Config& c,
                                                  std::string_view section) {
    for (const auto& l : config::listeners_of(c)) {
        if (l.section == section) return l;
    }
    return std::nullopt;
}

bool is_modbus(std::string_view protocol) { return protocol.rfind("modbus", 0) == 0; }

// The console and API name PLCs, not unit IDs: their listeners hold no station.
bool by_unit(std::string_view protocol) { return protocol != "http"; }

// One listener a set of PLCs asks for. PLCs with one key share it (the loader made sure they
// agree on its settings and its protocol).
struct Group {
    std::string key;  // config::listener_key; "#3 fatek.tcp" for a PLC's own port 0
    std::string_view protocol;
    std::string_view section;
    Carrier carrier = Carrier::Tcp;
    std::vector<std::size_t> members;
};

const config::Config& config_of(const config::Config& c) { return c; }
const config::Config& config_of(const ListenerMember& m) { return *m.config; }

// Every listener the PLCs ask for, each with its members. Every step below is linear in the
// PLCs (a map from key, from PLC): a config of 5,000 PLCs is grouped, refused and staged at a
// reload, where a quadratic step would hold every client for seconds.
template <typename Plcs>
std::vector<Group> group(const Plcs& plcs) {
    std::vector<Group> out;
    std::unordered_map<std::string, std::size_t> at;  // key -> its group in `out`
    for (std::size_t i = 0; i < plcs.size(); ++i) {
        for (const auto& l : config::listeners_of(config_of(plcs[i]))) {
            // Appended piece by piece: GCC 12's -Wrestrict takes `"#" + std::string&&` at -O2
            // for an overlapping copy (a false positive that -Werror would make fatal).
            std::string k;
            if (l.net != nullptr && l.net->port == 0) {
                k = "#";
                k += std::to_string(i);
                k += ' ';
                k += l.section;
            } else {
                k = config::listener_key(l);
            }
            const auto [it, fresh] = at.try_emplace(k, out.size());
            if (fresh) {
                out.push_back({std::move(k), l.protocol, l.section, l.carrier, {i}});
            } else {
                out[it->second].members.push_back(i);
            }
        }
    }
    return out;
}

// For each PLC, the groups (indexes into `groups`) it is a member of.
std::vector<std::vector<std::size_t>> groups_of(const std::vector<Group>& groups,
                                                std::size_t plcs) {
    std::vector<std::vector<std::size_t>> out(plcs);
    for (std::size_t g = 0; g < groups.size(); ++g) {
        for (const std::size_t i : groups[g].members) {
            if (i < plcs) out[i].push_back(g);
        }
    }
    return out;
}

// The members of the group of `section` that `plc` is in (its entry of groups_of()), or none.
const std::vector<std::size_t>& members_with(const std::vector<Group>& groups,
                                             const std::vector<std::size_t>& of_plc,
                                             std::string_view section) {
    static const std::vector<std::size_t> kNone;
    for (const std::size_t g : of_plc) {
        if (groups[g].section == section) return groups[g].members;
    }
    return kNone;
}

listener::UnknownUnit policy(const config::Config& c, std::string_view section) {
    return section == "modbus.tcp" && c.modbus.tcp.unknown_unit == config::UnknownUnit::Silent
               ? listener::UnknownUnit::Silent
               : listener::UnknownUnit::Refuse;
}

std::vector<listener::Seat> seats(const std::vector<std::size_t>& members,
                                  const std::vector<ListenerMember>& plcs) {
    std::vector<listener::Seat> v;
    v.reserve(members.size());
    for (std::size_t i : members) v.push_back(plcs[i].seat);
    return v;
}

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

struct Listeners::Listener {
    explicit Listener(const Group& g)
        : key(g.key),
          protocol(g.protocol),
          section(g.section),
          carrier(g.carrier),
          members(g.members) {}

    // "tcp", "rtu", "fatek udp": as logs and the status line name it.
    std::string what() const { return kind_words(protocol, carrier); }
    // Where it listens: the endpoint bound, or the device; the key while it is closed.
    std::string where() const {
        if (tcp) return tcp->endpoint();
        if (udp) return udp->endpoint();
        if (line) return line->description();
        return key.substr(key.find(' ') + 1);
    }
    bool open() const { return tcp || udp || line; }
    listener::UnitTable& units() { return stream ? stream->units() : serial->units(); }
    void stop() {
        if (tcp) tcp->stop();
        if (udp) udp->stop();
        if (line) line->stop();
    }
    bool has(std::size_t plc) const {
        return std::find(members.begin(), members.end(), plc) != members.end();
    }

    std::string key;
    std::string_view protocol;
    std::string_view section;
    Carrier carrier;
    std::vector<std::size_t> members;
    listener::TcpOptions options;   // TCP and UDP
    config::RtuConfig line_config;  // serial: the line's settings, as opened
    // What it speaks; the server holds it, so it outlives the server.
    std::unique_ptr<listener::StreamProtocol> stream;
    std::unique_ptr<listener::SerialProtocol> serial;
    std::unique_ptr<listener::TcpListener> tcp;
    std::unique_ptr<listener::UdpListener> udp;
    std::unique_ptr<listener::SerialListener> line;
};

struct Listeners::Plan {
    std::vector<Group> all;                    // every listener `next` asks for
    std::vector<std::vector<std::size_t>> of;  // for each PLC, its groups in `all`
};

namespace {

template <typename Plcs>
std::shared_ptr<const Listeners::Plan> plan_of(const Plcs& plcs) {
    auto p = std::make_shared<Listeners::Plan>();
    p->all = group(plcs);
    p->of = groups_of(p->all, plcs.size());
    return p;
}

}  // namespace

std::shared_ptr<const Listeners::Plan> Listeners::plan(const std::vector<config::Config>& next) {
    return plan_of(next);
}

void Listeners::reserve_descriptors(const std::vector<config::Config>& configs) {
    if (configs.empty()) return;
    std::vector<std::pair<std::string_view, int>> listeners;
    for (const auto& g : group(configs)) {
        if (g.carrier != Carrier::Tcp) continue;
        if (const auto l = listener_in(configs[g.members.front()], g.section))
            listeners.emplace_back(l->section, l->net->max_clients);
    }
    const auto [needed, what] = descriptors_for(listeners, configs.size());
    raise_soft_fd_limit(needed, what);
}

struct Listeners::Staged {
    std::size_t kept = 0;             // index into tcp_ when `fresh` is null
    std::unique_ptr<Listener> fresh;  // a new listener
};

Listeners::Listeners(asio::io_context& io, const listener::Census& census)
    : io_(io),
      census_(census) {}

Listeners::~Listeners() { stop(); }

namespace {

// A TCP listener of group `g`, its protocol made, its server not opened yet.
template <typename Plcs>
std::unique_ptr<Listeners::Listener> tcp_listener(const Group& g,
                                                  const Plcs& plcs,
                                                  listener::ClientRoom* room) {
    auto t = std::make_unique<Listeners::Listener>(g);
    const config::Config& c = config_of(plcs[g.members.front()]);
    t->options = net_options(*listener_in(c, g.section));
    t->options.room = room;
    // Its PLCs are seated by route().
    t->stream = protocol(g.protocol).stream({});
    return t;
}

}  // namespace

void Listeners::open(const std::vector<ListenerMember>& plcs) {
    plcs_ = plcs;
    in_force_ = plan_of(plcs);
    // Modbus TCP ports open last: a client that waits for one (the system tests, a supervisor's
    // probe) finds every other listener of the process open by then.
    open_reopened(plcs, {}, true);
    std::vector<const Group*> groups;
    for (const auto& g : in_force_->all) {
        if (g.carrier == Carrier::Tcp) groups.push_back(&g);
    }
    std::stable_partition(groups.begin(), groups.end(),
                          [](const Group* g) { return g->protocol != "modbus-tcp"; });
    for (const Group* g : groups) {
        auto t = tcp_listener(*g, plcs, &room_);
        t->tcp = std::make_unique<listener::TcpListener>(io_, *t->stream, t->options);
        tcp_.push_back(std::move(t));
    }
    route(plcs);
    describe_seats();
    raise_fd_limit(plcs.size());
    for (const auto& t : tcp_) log_listening(t->what(), t->where(), t->members, plcs_);
}

namespace {

// Whether the open UDP listener or serial line `r` can serve what group `g` asks for (`l` its
// settings) without being opened again: the same protocol, address (a port-0 listener's key
// does not hold it) or device, PLCs and line settings. Its access (`allow`, `read_only`) is
// then updated in place (keep()).
bool serves_as_is(const Listeners::Listener& r, const Group& g, const config::ListenerConfig& l) {
    if (!r.open() || r.key != g.key || r.protocol != g.protocol || r.members != g.members)
        return false;
    if (g.carrier == Carrier::Udp)
        return r.options.net.bind == l.net->bind && r.options.net.port == l.net->port;
    const config::RtuConfig& was = r.line_config;
    const config::RtuConfig& now = *l.line;
    // The path as written, too: a line lost is reopened by it, so a new link to the same
    // device (/dev/serial/by-id/... for /dev/ttyUSB0) must be the one it goes by.
    return was.device == now.device && was.baud == now.baud && was.parity == now.parity &&
           was.data_bits == now.data_bits && was.stop_bits == now.stop_bits && was.echo == now.echo;
}

// A UDP listener or serial line kept across a reload takes the new access settings and seats.
void keep(Listeners::Listener& r,
          const config::ListenerConfig& l,
          std::vector<listener::Seat> seated) {
    r.units().assign(std::move(seated));
    if (r.udp) {
        r.options.net = *l.net;
        r.udp->set_allow(l.net->allow);
        r.units().set_read_only(l.net->read_only);
    } else {
        r.line_config = *l.line;
        r.units().set_read_only(l.line->read_only);
    }
}

}  // namespace

void Listeners::open_reopened(const std::vector<ListenerMember>& plcs,
                              std::vector<std::unique_ptr<Listener>> running,
                              bool at_start) {
    // Those that serve their group as they are go on (a request half received on a line is
    // answered, a datagram queued is read); the others close before any opens, so that a
    // device or a port they hold is free for the new settings.
    std::unordered_map<std::string_view, const Group*> wanted;
    for (const auto& g : in_force_->all) {
        if (g.carrier != Carrier::Tcp) wanted.emplace(g.key, &g);
    }
    std::unordered_map<std::string_view, std::unique_ptr<Listener>> kept;
    for (auto& r : running) {
        const auto g = wanted.find(r->key);
        const auto l = g == wanted.end() ? std::nullopt
                                         : listener_in(*plcs[g->second->members.front()].config,
                                                       g->second->section);
        if (l && serves_as_is(*r, *g->second, *l)) {
            kept.emplace(g->first, std::move(r));
        } else {
            r->stop();
        }
    }
    running.clear();
    for (const auto& g : in_force_->all) {
        if (g.carrier == Carrier::Tcp) continue;
        if (const auto found = kept.find(g.key); found != kept.end()) {
            keep(*found->second, *listener_in(*plcs[g.members.front()].config, g.section),
                 seats(g.members, plcs));
            reopened_.push_back(std::move(found->second));
            continue;
        }
        auto r = std::make_unique<Listener>(g);
        const config::Config& c = *plcs[g.members.front()].config;
        const config::ListenerConfig l = *listener_in(c, g.section);
        listener::ProtocolSetup setup{seats(g.members, plcs), listener::UnknownUnit::Silent, {}};
        const std::string& label = c.label;
        const std::string prefix = g.members.size() == 1 && !label.empty() ? label + ": " : "";
        try {
            if (g.carrier == Carrier::Udp) {
                r->options = net_options(l);
                setup.read_only = l.net->read_only;
                r->stream = protocol(g.protocol).datagram(std::move(setup));
                r->udp = std::make_unique<listener::UdpListener>(
                    io_, *r->stream,
                    listener::UdpOptions{r->options.net.bind, r->options.net.port,
                                         r->options.net.allow, g.protocol});
            } else {
                const config::RtuConfig& s = *l.line;
                r->line_config = s;
                setup.line = {s.device, s.baud, s.parity, s.data_bits, s.stop_bits, s.echo};
                setup.read_only = s.read_only;
                r->serial = protocol(g.protocol).serial(setup);
                // At a reload a device that is not there (a USB adapter unplugged, a link not
                // yet made) is waited for with back-off, as one lost while open.
                r->line = std::make_unique<listener::SerialListener>(
                    io_, *r->serial, setup.line, r->what(), g.protocol, !at_start);
                // The console and the status line say while a line waits for its device.
                r->line->on_device_change([this] {
                    describe_seats();
                    if (on_change_) on_change_();
                });
                if (!r->line->absent().empty()) {
                    spdlog::error("reload: {}{}; trying it again with back-off{}", prefix,
                                  r->line->absent(),
                                  g.members.size() > 1 ? " for " + names(g.members, plcs_) : "");
                    reopened_.push_back(std::move(r));
                    continue;
                }
            }
        } catch (const std::exception& e) {
            if (at_start) throw;
            // The listener stays listed without a server: its PLCs keep their unit IDs there (a
            // station change is checked against them), and the next reload tries it again.
            // e.what() names it ("rtu: ...", "cannot listen on udp ...").
            spdlog::error("reload: {}{}; serving without {}{}", prefix, e.what(),
                          g.carrier == Carrier::Serial ? "the serial port" : "it",
                          g.members.size() > 1 ? " for " + names(g.members, plcs_) : "");
            reopened_.push_back(std::move(r));
            continue;
        }
        log_listening(r->what(), r->where(), r->members, plcs_);
        reopened_.push_back(std::move(r));
    }
}

void Listeners::route(const std::vector<ListenerMember>& plcs) {
    for (auto& t : tcp_) {
        const config::Config& c = *plcs[t->members.front()].config;
        t->units().assign(seats(t->members, plcs));
        t->units().set_unknown_unit(policy(c, t->section));
        const auto l = listener_in(c, t->section);
        t->units().set_read_only(l && l->net->read_only);
        t->units().set_token(l ? l->net->token : std::string());
        t->units().set_hosts(l ? l->net->hosts : std::vector<std::string>());
        t->units().set_census(&census_);
    }
}

std::vector<listener::ConnectionFigures> Listeners::connections() const {
    std::vector<listener::ConnectionFigures> out;
    for (const auto& t : tcp_) {
        if (t->tcp) out.push_back(t->tcp->figures());
    }
    return out;
}

void Listeners::describe_seats() {
    // What the console shows of each PLC: its listeners, once every one is open.
    std::vector<std::string> described;
    for (auto& t : tcp_) {
        if (by_unit(t->protocol)) continue;
        if (described.empty()) described = describe_all();
        std::vector<listener::Seat> seated = t->units().seats();
        for (std::size_t k = 0; k < seated.size(); ++k) {
            const std::string& d = described[t->members[k]];
            seated[k].listeners = d.size() > 2 ? d.substr(2) : d;
        }
        t->units().assign(std::move(seated));
    }
}

void Listeners::raise_fd_limit(std::size_t plcs) {
    if (tcp_.empty()) return;
    // One descriptor per client of every listener, and the few each further PLC holds.
    std::vector<std::pair<std::string_view, int>> listeners;
    for (const auto& t : tcp_)
        listeners.emplace_back(t->options.section, t->options.net.max_clients);
    const auto [needed, what] = descriptors_for(listeners, plcs);
    const long limit = ensure_fd_limit(needed, what, room_.open);
    // The clients of all listeners together may take what is left once the daemon's own
    // descriptors and a reload's files are counted: beyond it they wait at accept, and a
    // reload can still open its config.
    const long in_use = open_descriptors();
    room_.room =
        limit < 0 || in_use < 0 ? -1 : std::max(0L, limit - (in_use - room_.open) - kFdHeadroom);
}

std::string Listeners::refusal(const std::vector<config::Config>& next, const Plan& plan) const {
    // The listeners as they are: the plan of the configs last opened or applied.
    const std::vector<Group>& before = in_force_->all;
    const auto& before_of = in_force_->of;
    const std::vector<Group>& after = plan.all;
    const auto& after_of = plan.of;
    // A reload keeps the number of PLCs (the daemon refuses it first otherwise).
    for (std::size_t i = 0; i < next.size() && i < before_of.size(); ++i) {
        for (const auto& [groups, of] :
             {std::pair{&std::as_const(before), &before_of}, std::pair{&after, &after_of}}) {
            for (const std::size_t k : (*of)[i]) {
                const Group& g = (*groups)[k];
                const auto& was = members_with(before, before_of[i], g.section);
                const auto& now = members_with(after, after_of[i], g.section);
                if ((was.size() > 1 || now.size() > 1) && was != now) {
                    const char* what = g.carrier == Carrier::Serial ? "serial line"
                                       : g.carrier == Carrier::Udp  ? "udp listener"
                                                                    : "tcp listener";
                    return next[i].label + ": the PLCs sharing its " +
                           (is_modbus(g.protocol) ? "" : std::string(g.protocol) + " ") + what +
                           " changed; restart plcemud to apply it";
                }
            }
        }
    }
    return {};
}

bool Listeners::stage(const std::vector<config::Config>& next, std::shared_ptr<const Plan> plan) {
    staged_.clear();
    staged_plan_.reset();
    stopped_for_stage_.clear();
    // A UDP port the reload moves to must be free, as a TCP one must: the socket opens at the
    // apply, after the old one closed, and a port in use then left the PLC without it. Tried
    // here, beside the running ones; a port a running UDP listener holds is freed at the apply.
    // One that goes on at the same endpoint needs no try (a reload of 5,000 PLCs would make
    // 5,000 sockets on the loop).
    std::unordered_map<std::string_view, const Listener*> running_udp;
    for (const auto& r : reopened_) {
        if (r->udp) running_udp.emplace(r->key, r.get());
    }
    for (const auto& g : plan->all) {
        if (g.carrier != Carrier::Udp) continue;
        const config::TcpConfig& net = *listener_in(next[g.members.front()], g.section)->net;
        if (const auto r = running_udp.find(g.key); r != running_udp.end() &&
                                                    r->second->options.net.bind == net.bind &&
                                                    r->second->options.net.port == net.port) {
            continue;
        }
        asio::error_code ec;
        const auto address = asio::ip::make_address(net.bind, ec);
        asio::ip::udp::socket probe(io_);
        if (!ec) probe.open(address.is_v6() ? asio::ip::udp::v6() : asio::ip::udp::v4(), ec);
        if (!ec) probe.bind({address, net.port}, ec);
        if (!ec) continue;
        // In use by one of ours (kept as it is, or closed before the new one opens): fine.
        const bool ours = std::any_of(reopened_.begin(), reopened_.end(), [&](const auto& r) {
            return r->udp && r->udp->port() == net.port;
        });
        if (ec == asio::error::address_in_use && ours) continue;
        const std::string& label = next[g.members.front()].label;
        spdlog::error("reload: {}cannot listen on {} {}:{} ({}): {}",
                      label.empty() ? "" : label + ": ", kind_words(g.protocol, g.carrier),
                      net.bind, net.port, g.section, ec.message());
        return false;
    }
    // The running TCP listener of each PLC and section.
    std::map<std::pair<std::size_t, std::string_view>, std::size_t> running_of;
    for (std::size_t t = 0; t < tcp_.size(); ++t) {
        for (const std::size_t i : tcp_[t]->members)
            running_of.try_emplace({i, tcp_[t]->section}, t);
    }
    // The running listener of the same PLCs as `g`, if any (refusal() made sure the members are
    // the same ones when shared).
    const auto running_for = [&](const Group& g) {
        const auto found = running_of.find({g.members.front(), g.section});
        return found == running_of.end()
                   ? tcp_.end()
                   : tcp_.begin() + static_cast<std::ptrdiff_t>(found->second);
    };
    // Whether the running listener serves `g` as it is: the same key and address (a port-0
    // listener's key does not hold its address).
    const auto same = [&](const Listener& t, const Group& g) {
        return t.key == g.key &&
               t.options.net.bind == listener_in(next[g.members.front()], g.section)->net->bind;
    };
    // The running listeners this reload keeps; the others close once it is applied.
    std::vector<bool> kept(tcp_.size(), false);
    // New listeners whose port was in use: staged_'s index, the log prefix, the error.
    struct InUse {
        std::size_t index;
        std::string prefix;
        std::string what;
    };
    std::vector<InUse> in_use;
    for (const auto& g : plan->all) {
        if (g.carrier != Carrier::Tcp) continue;
        const auto running = running_for(g);
        if (running != tcp_.end() && same(**running, g))
            kept[static_cast<std::size_t>(running - tcp_.begin())] = true;
    }
    for (const auto& g : plan->all) {
        if (g.carrier != Carrier::Tcp) continue;
        const std::size_t first = g.members.front();
        const auto running = running_for(g);
        Staged s;
        if (running != tcp_.end() && same(**running, g)) {
            s.kept = static_cast<std::size_t>(running - tcp_.begin());
            staged_.push_back(std::move(s));
            continue;
        }
        s.fresh = tcp_listener(g, next, &room_);
        const std::string& label = next[first].label;
        const std::string prefix = label.empty() ? "" : label + ": ";
        try {
            s.fresh->tcp =
                std::make_unique<listener::TcpListener>(io_, *s.fresh->stream, s.fresh->options);
        } catch (const std::system_error& e) {
            // A port in use may be held by running listeners this reload closes anyway: tried
            // again below, once every other listener is had. Anything else (an address not of
            // this host) refuses the reload before any client is disturbed.
            // e.what() names the endpoint ("cannot listen on tcp ADDR:PORT: ...").
            if (e.code() != asio::error::address_in_use || s.fresh->options.net.port == 0) {
                spdlog::error("reload: {}{}", prefix, e.what());
                unstage();
                return false;
            }
            in_use.push_back({staged_.size(), prefix, e.what()});
        } catch (const std::exception& e) {
            spdlog::error("reload: {}{}", prefix, e.what());
            unstage();
            return false;
        }
        staged_.push_back(std::move(s));
    }
    // The ports in use: the running listeners that hold them and that this reload closes (the
    // PLC's own on another address, 127.0.0.1 -> 0.0.0.0, or another PLC's that moves
    // elsewhere) go first; if the new one still fails, they come back. A port none of those
    // holds is in use elsewhere: refused before any is closed.
    const auto holds = [&](std::size_t t, std::uint16_t port) {
        // By the port bound: a port-0 listener's is the kernel's.
        return !kept[t] && tcp_[t]->tcp && tcp_[t]->tcp->port() == port;
    };
    for (const auto& [index, prefix, what] : in_use) {
        bool held = false;
        for (std::size_t t = 0; t < tcp_.size(); ++t)
            held = held || holds(t, staged_[index].fresh->options.net.port);
        if (!held) {
            spdlog::error("reload: {}{}", prefix, what);
            unstage();
            return false;
        }
    }
    for (const auto& [index, prefix, what] : in_use) {
        Listener& fresh = *staged_[index].fresh;
        const auto port = fresh.options.net.port;
        bool freed = false;
        for (std::size_t t = 0; t < tcp_.size(); ++t) {
            Listener& held = *tcp_[t];
            if (!holds(t, port)) continue;
            spdlog::info("reload: {}closing {} {} to listen on {}:{}", prefix, held.what(),
                         held.where(), fresh.options.net.bind, port);
            held.tcp->stop();
            held.tcp.reset();
            stopped_for_stage_.push_back(t);
            freed = true;
        }
        try {
            if (!freed) throw std::runtime_error(what);
            fresh.tcp = std::make_unique<listener::TcpListener>(io_, *fresh.stream, fresh.options);
        } catch (const std::exception& e) {
            spdlog::error("reload: {}{}", prefix, e.what());
            unstage();
            return false;
        }
    }
    staged_plan_ = std::move(plan);
    return true;
}

void Listeners::unstage() {
    for (auto& s : staged_) {
        if (s.fresh) s.fresh->stop();
    }
    staged_.clear();
    staged_plan_.reset();
    // The previous listeners again, after a reload that had to close them failed.
    for (std::size_t i : stopped_for_stage_) {
        Listener& t = *tcp_[i];
        try {
            t.tcp = std::make_unique<listener::TcpListener>(io_, *t.stream, t.options);
        } catch (const std::exception& e) {
            spdlog::error("{}: cannot listen on {} again: {}; serving nothing there", t.what(),
                          t.key, e.what());
        }
    }
    stopped_for_stage_.clear();
}

void Listeners::apply(const std::vector<ListenerMember>& plcs, bool as_staged) {
    std::vector<std::unique_ptr<Listener>> now;
    for (auto& s : staged_) {
        if (s.fresh) {
            now.push_back(std::move(s.fresh));
            log_listening(now.back()->what(), now.back()->where(), now.back()->members, plcs_);
            continue;
        }
        auto kept = std::move(tcp_[s.kept]);
        const config::Config& c = *plcs[kept->members.front()].config;
        kept->options = net_options(*listener_in(c, kept->section));
        kept->options.room = &room_;
        if (kept->tcp) kept->tcp->set_limits(kept->options);
        now.push_back(std::move(kept));
    }
    staged_.clear();
    stopped_for_stage_.clear();
    for (auto& t : tcp_) {
        if (t) t->stop();  // not kept: its PLCs left it
    }
    tcp_ = std::move(now);
    plcs_ = plcs;
    // A copy: the staged plan was made on the reload's thread, and its thousands of small
    // blocks, kept, would hold that thread's heap pages after the reload (27 MB more RSS at
    // 5,000 PLCs). The copy costs the loop about a millisecond there.
    in_force_ = as_staged ? std::make_shared<const Plan>(*staged_plan_) : plan_of(plcs);
    staged_plan_.reset();
    route(plcs);
    raise_fd_limit(plcs.size());
    // UDP listeners and serial lines whose settings changed are opened again with the new ones,
    // as is one that could not be opened before (a device that came back is tried).
    std::vector<std::unique_ptr<Listener>> running;
    running.swap(reopened_);
    open_reopened(plcs, std::move(running), false);
    describe_seats();
}

void Listeners::stop() {
    for (auto& t : tcp_) {
        if (t) t->stop();
    }
    for (auto& s : staged_) {
        if (s.fresh) s.fresh->stop();
    }
    for (auto& r : reopened_) r->stop();
}

std::string Listeners::holder(std::size_t index, std::uint8_t unit) const {
    for (const auto* list : {&tcp_, &reopened_}) {
        for (const auto& l : *list) {
            if (!l->has(index) || !by_unit(l->protocol)) continue;
            // A PLC on port 0 has a key of its own ("#3 modbus.tcp"): the port it got says more.
            const std::string where = l->carrier == Carrier::Serial
                                          ? (is_modbus(l->protocol) ? "" : l->what() + " ") +
                                                "serial line " + l->key.substr(7)
                                          : l->what() + " " + l->where();
            for (std::size_t j : l->members) {
                const listener::Seat& d = plcs_[j].seat;
                const bool sim =
                    is_modbus(l->protocol) && d.simulator != nullptr && d.simulator_unit == unit;
                const char* what = j != index && *d.station == unit ? " station on "
                                   : sim                            ? " simulator unit on "
                                                                    : nullptr;
                if (what == nullptr) continue;
                std::string who = j == index ? "its own" : plcs_[j].config->label + "'s";
                who += what;
                who += where;
                return who;
            }
        }
    }
    return {};
}

std::string Listeners::unit_clash(const std::vector<config::Config>& next,
                                  const std::vector<std::uint8_t>& stations,
                                  const Plan& plan) const {
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
    for (const auto& g : plan.all) {
        if (!by_unit(g.protocol)) continue;
        const std::string what = (is_modbus(g.protocol) ? "" : std::string(g.protocol) + " ") +
                                 (g.carrier == Carrier::Serial ? "serial line "
                                  : g.carrier == Carrier::Udp  ? "udp listener "
                                                               : "tcp listener ");
        const std::string where = " on the shared " + what + g.key.substr(g.key.find(' ') + 1);
        for (std::size_t a = 0; a < g.members.size(); ++a) {
            for (std::size_t b = 0; b < a; ++b) {
                const std::size_t i = g.members[a];
                const std::size_t j = g.members[b];
                if (stations[i] == stations[j]) {
                    return next[i].label + ": its " + station(i) + " is also " + next[j].label +
                           "'s " + station(j) + where;
                }
                if (!is_modbus(g.protocol)) continue;
                for (const auto& [x, y] : {std::pair{i, j}, std::pair{j, i}}) {
                    if (next[y].simulator.unit == stations[x]) {
                        return next[x].label + ": its " + station(x) + " is also " + next[y].label +
                               "'s simulator unit" + where;
                    }
                }
            }
        }
    }
    return {};
}

std::vector<std::string> Listeners::describe_all(std::size_t plcs) const {
    std::vector<std::string> out(std::min(plcs, plcs_.size()));
    for (const auto* list : {&tcp_, &reopened_}) {
        for (const auto& l : *list) {
            if (!l->open()) continue;
            // Its members are in `plcs:` order.
            if (l->members.empty() || l->members.front() >= out.size()) continue;
            std::string words = ", " + l->what() + " " + l->where();
            if (l->line && !l->line->has_device()) words += " (waiting for the device)";
            for (const std::size_t i : l->members) {
                if (i < out.size()) out[i] += words;
            }
        }
    }
    return out;
}

}  // namespace plcemu::daemon
