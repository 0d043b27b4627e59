#include "reload.hpp"

#include <algorithm>
#include <sstream>

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

std::string text(const std::optional<config::RtuConfig>& r) {
    if (!r) return "none";
    return r->device + " " + std::to_string(r->baud) + " " + std::string(1, r->parity) +
           std::to_string(r->data_bits) + std::to_string(r->stop_bits);
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

std::vector<std::string> config_changes(const config::Config& a, const config::Config& b) {
    std::vector<std::string> out;
    auto cmp = [&](const std::string& key, const auto& x, const auto& y) {
        if (!(x == y)) out.push_back(key + ": " + text(x) + " -> " + text(y));
    };
    cmp("model", a.model, b.model);
    cmp("station", int(a.station), int(b.station));
    cmp("scan_ms", a.scan_ms, b.scan_ms);
    cmp("time_scale", a.time_scale, b.time_scale);
    cmp("modbus.tcp.enabled", a.modbus.tcp.enabled, b.modbus.tcp.enabled);
    cmp("modbus.tcp.bind", a.modbus.tcp.bind, b.modbus.tcp.bind);
    cmp("modbus.tcp.port", a.modbus.tcp.port, b.modbus.tcp.port);
    cmp("modbus.tcp.unknown_unit",
        std::string(a.modbus.tcp.unknown_unit == config::UnknownUnit::Silent ? "silent"
                                                                             : "exception"),
        std::string(b.modbus.tcp.unknown_unit == config::UnknownUnit::Silent ? "silent"
                                                                             : "exception"));
    cmp("modbus.tcp.allow", a.modbus.tcp.allow, b.modbus.tcp.allow);
    cmp("modbus.tcp.max_clients", a.modbus.tcp.max_clients, b.modbus.tcp.max_clients);
    cmp("modbus.tcp.idle_timeout_s", a.modbus.tcp.idle_timeout_s, b.modbus.tcp.idle_timeout_s);
    cmp("modbus.tcp.frame_timeout_ms", a.modbus.tcp.frame_timeout_ms,
        b.modbus.tcp.frame_timeout_ms);
    if (rtu_changed(a, b)) {
        out.push_back("modbus.rtu: " + text(a.modbus.rtu) + " -> " + text(b.modbus.rtu));
    }
    cmp("http", std::string(a.http ? "on" : "off"), std::string(b.http ? "on" : "off"));
    if (a.http && b.http) {
        cmp("http.bind", a.http->bind, b.http->bind);
        cmp("http.port", a.http->port, b.http->port);
        cmp("http.allow", a.http->allow, b.http->allow);
        cmp("http.hosts", a.http->hosts, b.http->hosts);
        cmp("http.read_only", a.http->read_only, b.http->read_only);
        cmp("http.max_clients", a.http->max_clients, b.http->max_clients);
        cmp("http.idle_timeout_s", a.http->idle_timeout_s, b.http->idle_timeout_s);
        cmp("http.frame_timeout_ms", a.http->frame_timeout_ms, b.http->frame_timeout_ms);
        // A secret: said to have changed, never shown.
        if (a.http->token != b.http->token) out.emplace_back("http.token: changed");
    }
    cmp("modbus.read_only", a.modbus.read_only, b.modbus.read_only);
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
    cmp("simulator.unit", a.simulator.unit, b.simulator.unit);
    cmp("simulator.writable",
        a.simulator.writable ? text(*a.simulator.writable) : std::string("default"),
        b.simulator.writable ? text(*b.simulator.writable) : std::string("default"));
    cmp("persistence.enabled", a.persistence.enabled, b.persistence.enabled);
    cmp("persistence.file", a.persistence.file, b.persistence.file);
    if (a.persistence.retentive != b.persistence.retentive) {
        out.push_back("persistence.retentive: changed");
    }
    cmp("persistence.sync_ms", a.persistence.sync_ms, b.persistence.sync_ms);
    cmp("persistence.init",
        std::string(a.persistence.init == config::InitPolicy::Always ? "always" : "fresh"),
        std::string(b.persistence.init == config::InitPolicy::Always ? "always" : "fresh"));
    return out;
}

bool rtu_changed(const config::Config& a, const config::Config& b) {
    const auto& x = a.modbus.rtu;
    const auto& y = b.modbus.rtu;
    if (x.has_value() != y.has_value()) return true;
    if (!x) return false;
    return x->device != y->device || x->baud != y->baud || x->parity != y->parity ||
           x->data_bits != y->data_bits || x->stop_bits != y->stop_bits;
}

}  // namespace plcemu::daemon
