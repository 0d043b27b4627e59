#include "reload.hpp"

#include <algorithm>
#include <sstream>

#include "plcemu/config/listener_key.hpp"
#include "plcemu/profiles/profile.hpp"

namespace plcemu::daemon {

namespace {

template <typename T>
std::string text(const T& v) {
    std::ostringstream o;
    o << v;
    return o.str();
}

std::string text(bool v) { return v ? "true" : "false"; }

std::string text(const std::vector<std::string>& v) {
    std::string s = "[";
    for (const auto& e : v) s += (s.size() > 1 ? ", " : "") + e;
    return s + "]";
}

std::string text(const std::vector<config::Cidr>& v) {
    std::string s = "[";
    for (const auto& e : v) s += (s.size() > 1 ? ", " : "") + e.text;
    return s + "]";
}

std::string text(const std::vector<image::Range>& v, const image::Naming& naming) {
    std::string s = "[";
    for (const auto& r : v) s += (s.size() > 1 ? ", " : "") + naming.format_range(r);
    return s + "]";
}

// As the listening line says it: "/dev/ttyS0 9600 8E1".
std::string text(const std::optional<config::RtuConfig>& r) {
    if (!r) return "none";
    return r->device + " " + std::to_string(r->baud) + " " + std::to_string(r->data_bits) +
           std::string(1, r->parity) + std::to_string(r->stop_bits);
}

std::string text(config::UnknownUnit u) {
    return u == config::UnknownUnit::Silent ? "silent" : "exception";
}

using Out = std::vector<std::string>;

template <typename T>
void compare(Out& out, const std::string& key, const T& x, const T& y) {
    if (!(x == y)) out.push_back(key + ": " + text(x) + " -> " + text(y));
}

// A TCP or UDP listener's settings (modbus.tcp, fatek.tcp, fatek.udp, http), each that changed;
// "on"/"off" when one side has none. A key a listener does not use keeps its default on both
// sides and says nothing.
void net_changes(Out& out,
                 const std::string& name,
                 const config::TcpConfig* a,
                 const config::TcpConfig* b) {
    if ((a == nullptr) != (b == nullptr)) {
        out.push_back(name + ": " + (a ? "on" : "off") + " -> " + (b ? "on" : "off"));
    }
    if (a == nullptr || b == nullptr) return;
    compare(out, name + ".bind", a->bind, b->bind);
    compare(out, name + ".port", a->port, b->port);
    compare(out, name + ".unknown_unit", a->unknown_unit, b->unknown_unit);
    compare(out, name + ".allow", a->allow, b->allow);
    compare(out, name + ".hosts", a->hosts, b->hosts);
    compare(out, name + ".read_only", a->read_only, b->read_only);
    compare(out, name + ".max_clients", a->max_clients, b->max_clients);
    compare(out, name + ".idle_timeout_s", a->idle_timeout_s, b->idle_timeout_s);
    compare(out, name + ".frame_timeout_ms", a->frame_timeout_ms, b->frame_timeout_ms);
    // A secret: said to have changed, never shown.
    if (a->token != b->token) out.push_back(name + ".token: changed");
}

// A serial line's settings (modbus.rtu, fatek.serial), as one value.
void line_changes(Out& out,
                  const std::string& name,
                  const std::optional<config::RtuConfig>& a,
                  const std::optional<config::RtuConfig>& b) {
    const bool same =
        a.has_value() == b.has_value() &&
        (!a || (a->device == b->device && a->baud == b->baud && a->parity == b->parity &&
                a->data_bits == b->data_bits && a->stop_bits == b->stop_bits));
    if (!same) out.push_back(name + ": " + text(a) + " -> " + text(b));
    if (a && b) compare(out, name + ".read_only", a->read_only, b->read_only);
    if (a && b) compare(out, name + ".echo", a->echo, b->echo);
}

const config::TcpConfig* net(const std::optional<config::TcpConfig>& c) {
    return c ? &*c : nullptr;
}

bool same_program(const std::vector<config::InstructionConfig>& a,
                  const std::vector<config::InstructionConfig>& b) {
    if (a.size() != b.size()) return false;
    for (std::size_t i = 0; i < a.size(); ++i) {
        if (a[i].mnemonic != b[i].mnemonic || a[i].operands.size() != b[i].operands.size()) {
            return false;
        }
        for (std::size_t k = 0; k < a[i].operands.size(); ++k) {
            if (a[i].operands[k].first != b[i].operands[k].first ||
                a[i].operands[k].second.text != b[i].operands[k].second.text) {
                return false;
            }
        }
    }
    return true;
}

bool same_init(const std::vector<config::InitEntry>& a, const std::vector<config::InitEntry>& b) {
    if (a.size() != b.size()) return false;
    for (std::size_t i = 0; i < a.size(); ++i) {
        if (!(a[i].device == b[i].device) || a[i].values != b[i].values) return false;
    }
    return true;
}

// The profile's own sections (`temperature:`, `modules:`), compared as written.
const config::Node* section(const config::Config& c, const std::string& name) {
    for (const auto& [n, node] : c.sections) {
        if (n == name) return &node;
    }
    return nullptr;
}

void changed_sections(const config::Config& a,
                      const config::Config& b,
                      std::vector<std::string>& out) {
    std::vector<std::string> names;
    for (const auto* c : {&a, &b}) {
        for (const auto& [n, node] : c->sections) {
            if (std::find(names.begin(), names.end(), n) == names.end()) names.push_back(n);
        }
    }
    for (const auto& n : names) {
        const config::Node* x = section(a, n);
        const config::Node* y = section(b, n);
        if (x == nullptr || y == nullptr || !x->same(*y)) out.push_back(n + ": changed");
    }
}

bool same_map(const std::optional<std::vector<config::MapRowConfig>>& a,
              const std::optional<std::vector<config::MapRowConfig>>& b) {
    if (a.has_value() != b.has_value()) return false;
    if (!a) return true;
    if (a->size() != b->size()) return false;
    for (std::size_t i = 0; i < a->size(); ++i) {
        const auto& x = (*a)[i];
        const auto& y = (*b)[i];
        if (x.table != y.table || x.start != y.start || !(x.device == y.device) ||
            x.count != y.count || x.read_only != y.read_only) {
            return false;
        }
    }
    return true;
}

}  // namespace

std::vector<std::string> config_changes(const config::Config& a,
                                        const config::Config& b,
                                        const std::string& state_directory) {
    std::vector<std::string> out;
    compare(out, "model", a.model, b.model);
    compare(out, "station", int(a.station), int(b.station));
    compare(out, "scan_ms", a.scan_ms, b.scan_ms);
    compare(out, "time_scale", a.time_scale, b.time_scale);
    compare(out, "modbus.tcp.enabled", a.modbus.tcp.enabled, b.modbus.tcp.enabled);
    net_changes(out, "modbus.tcp", &a.modbus.tcp, &b.modbus.tcp);
    line_changes(out, "modbus.rtu", a.modbus.rtu, b.modbus.rtu);
    net_changes(out, "fatek.tcp", net(a.fatek.tcp), net(b.fatek.tcp));
    net_changes(out, "fatek.udp", net(a.fatek.udp), net(b.fatek.udp));
    line_changes(out, "fatek.serial", a.fatek.serial, b.fatek.serial);
    net_changes(out, "http", net(a.http), net(b.http));
    compare(out, "modbus.read_only", a.modbus.read_only, b.modbus.read_only);
    if (a.modbus.write_protect != b.modbus.write_protect) {
        const image::Naming& naming = profiles::of(b).naming();
        out.push_back("modbus.write_protect: " + text(a.modbus.write_protect, naming) + " -> " +
                      text(b.modbus.write_protect, naming));
    }
    if (!same_map(a.modbus.map, b.modbus.map)) out.push_back("modbus.map: changed");
    if (!same_init(a.init, b.init)) {
        out.push_back("init: changed (" + std::to_string(b.init.size()) + " entries)");
    }
    if (!same_program(a.program, b.program)) {
        out.push_back("program: changed (" + std::to_string(b.program.size()) + " instructions)");
    }
    // A program file is read again at each reload: an edit of the file alone is a change.
    const auto line_text = [](const config::ListingLineConfig& l) { return l.text; };
    if (!std::ranges::equal(a.listing, b.listing, {}, line_text, line_text)) {
        out.push_back("program: instruction list changed (" + std::to_string(b.listing.size()) +
                      " lines)");
    }
    changed_sections(a, b, out);
    const auto plant = config::plant_changes(a.plant, b.plant, profiles::of(b).naming());
    out.insert(out.end(), plant.begin(), plant.end());
    // The faults log themselves as they switch (listener::CommFaults): one line says they will.
    if (!(a.faults == b.faults)) out.emplace_back("faults: changed");
    compare(out, "simulator.unit", a.simulator.unit, b.simulator.unit);
    compare(out, "simulator.writable",
            a.simulator.writable ? text(*a.simulator.writable) : std::string("default"),
            b.simulator.writable ? text(*b.simulator.writable) : std::string("default"));
    compare(out, "persistence.enabled", a.persistence.enabled, b.persistence.enabled);
    // The same file written otherwise ("sub/x.state", "./sub/x.state") is no change; the paths
    // are resolved (their links walked) only when written otherwise.
    if (a.persistence.file != b.persistence.file &&
        config::state_file_key(config::state_file_path(a, state_directory)) !=
            config::state_file_key(config::state_file_path(b, state_directory))) {
        compare(out, "persistence.file",
                a.persistence.file.empty() ? std::string("default") : a.persistence.file,
                b.persistence.file.empty() ? std::string("default") : b.persistence.file);
    }
    const auto& ra = a.persistence.retentive;
    const auto& rb = b.persistence.retentive;
    if (ra.has_value() != rb.has_value() || (ra && !image::same_devices(*ra, *rb))) {
        out.push_back("persistence.retentive: changed");
    }
    compare(out, "persistence.sync_ms", a.persistence.sync_ms, b.persistence.sync_ms);
    compare(out, "persistence.init",
            std::string(a.persistence.init == config::InitPolicy::Always ? "always" : "fresh"),
            std::string(b.persistence.init == config::InitPolicy::Always ? "always" : "fresh"));
    return out;
}

}  // namespace plcemu::daemon
