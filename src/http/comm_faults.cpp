#include "http/comm_faults.hpp"

#include <algorithm>
#include <array>
#include <string_view>

#include "plcemu/config/comm_faults.hpp"
#include "plcemu/image/excerpt.hpp"

namespace plcemu::http {

namespace {

using config::CommFaultSettings;

// The fields a body may hold: the config's names, and the three a GET adds (ignored, so that
// what a GET said can be PUT back).
constexpr std::array<std::string_view, 18> kKeys{"delay_ms",
                                                 "drop_every",
                                                 "drop_probability",
                                                 "seed",
                                                 "exception",
                                                 "offline",
                                                 "refuse_connections",
                                                 "disconnect_after",
                                                 "reset",
                                                 "garble",
                                                 "stop",
                                                 "unit",
                                                 "function",
                                                 "from",
                                                 "count",
                                                 "active",
                                                 "summary",
                                                 "figures"};

Json describe(const listener::Seat& plc) {
    const listener::CommFaults& f = *plc.faults;
    const CommFaultSettings& s = f.settings();
    Json j;
    j["active"] = f.active();
    j["delay_ms"] = s.delay_min_ms == s.delay_max_ms
                        ? Json(s.delay_max_ms)
                        : Json::array({s.delay_min_ms, s.delay_max_ms});
    j["drop_every"] = s.drop_every;
    j["drop_probability"] = s.drop_probability;
    j["seed"] = s.seed;
    j["exception"] = s.exception;
    j["offline"] = s.offline;
    j["refuse_connections"] = s.refuse_connections;
    j["disconnect_after"] = s.disconnect_after ? Json(*s.disconnect_after) : Json(nullptr);
    j["reset"] = s.reset;
    j["garble"] = config::garble_name(s.garble);
    j["stop"] = s.stop;
    j["unit"] = s.unit;
    j["function"] = s.function;
    j["from"] = s.devices ? Json(plc.naming->format_device(s.devices->area, s.devices->start))
                          : Json(nullptr);
    j["count"] = s.devices ? plc.naming->devices_in(*s.devices) : 0;
    Json lines = Json::array();
    for (const auto& l : config::comm_fault_lines(s)) lines.push_back(l);
    j["summary"] = Json{{"faults", lines}, {"scope", config::comm_fault_scope(s, *plc.naming)}};
    const auto& n = f.figures();
    j["figures"] =
        Json{{"delayed", n.delayed},   {"dropped", n.dropped},           {"refused", n.refused},
             {"silenced", n.silenced}, {"disconnected", n.disconnected}, {"garbled", n.garbled}};
    return j;
}

// An integer in [lo, hi] at `key` of `o` into `out`; a refusal when it is another thing.
std::optional<Response> integer(
    const Json& o, const char* key, long long lo, long long hi, std::uint32_t& out) {
    const auto it = o.find(key);
    if (it == o.end()) return std::nullopt;
    if (!whole_in(*it, lo, hi)) {
        return error(400, std::string(key) + ": expected an integer from " + std::to_string(lo) +
                              " to " + std::to_string(hi));
    }
    out = static_cast<std::uint32_t>(it->get<long long>());
    return std::nullopt;
}

std::optional<Response> flag(const Json& o, const char* key, bool& out) {
    const auto it = o.find(key);
    if (it == o.end()) return std::nullopt;
    if (!it->is_boolean()) return error(400, std::string(key) + ": expected true or false");
    out = it->get<bool>();
    return std::nullopt;
}

// The settings a body says; a key left out is off.
std::optional<Response> read(const Json& b, const listener::Seat& plc, CommFaultSettings& s) {
    for (const auto& [k, v] : b.items()) {
        if (std::find(kKeys.begin(), kKeys.end(), k) == kKeys.end()) {
            return error(400, image::excerpt(k, 40) +
                                  ": unknown key (expected delay_ms, drop_every, "
                                  "drop_probability, seed, exception, offline, "
                                  "refuse_connections, disconnect_after, reset, garble, stop, "
                                  "unit, function, from or count)");
        }
    }
    constexpr long long kMs = config::kMaxCommDelayMs;
    constexpr long long kN = config::kMaxCommCount;
    if (const auto d = b.find("delay_ms"); d != b.end()) {
        const auto ms = [&](const Json& x) { return whole_in(x, 0, kMs); };
        if (ms(*d)) {
            s.delay_min_ms = s.delay_max_ms = d->get<std::uint32_t>();
        } else if (d->is_array() && d->size() == 2 && ms((*d)[0]) && ms((*d)[1]) &&
                   (*d)[0].get<long long>() <= (*d)[1].get<long long>()) {
            s.delay_min_ms = (*d)[0].get<std::uint32_t>();
            s.delay_max_ms = (*d)[1].get<std::uint32_t>();
        } else {
            return error(400, "delay_ms: expected ms from 0 to " + std::to_string(kMs) +
                                  ", or [min, max] with min at most max");
        }
    }
    std::uint32_t u = 0;
    if (auto r = integer(b, "drop_every", 0, kN, s.drop_every)) return r;
    if (const auto p = b.find("drop_probability"); p != b.end()) {
        if (!p->is_number() || p->get<double>() < 0 || p->get<double>() > 1)
            return error(400, "drop_probability: expected a number from 0 to 1");
        s.drop_probability = p->get<double>();
    }
    if (auto r = integer(b, "seed", 0, 0xFFFFFFFFLL, s.seed)) return r;
    if (auto r = integer(b, "exception", 0, 255, u)) return r;
    s.exception = static_cast<std::uint8_t>(b.contains("exception") ? u : 0);
    if (auto r = flag(b, "offline", s.offline)) return r;
    if (auto r = flag(b, "refuse_connections", s.refuse_connections)) return r;
    if (const auto d = b.find("disconnect_after"); d != b.end() && !d->is_null()) {
        if (auto r = integer(b, "disconnect_after", 0, kN, u)) return r;
        s.disconnect_after = u;
    }
    if (auto r = flag(b, "reset", s.reset)) return r;
    if (const auto g = b.find("garble"); g != b.end() && !g->is_null()) {
        const auto kind =
            g->is_string() ? config::garble_named(g->get<std::string>()) : std::nullopt;
        if (!kind) return error(400, "garble: expected \"crc\", \"short\", \"gap\" or \"none\"");
        s.garble = *kind;
    }
    if (auto r = flag(b, "stop", s.stop)) return r;
    u = 0;
    if (auto r = integer(b, "unit", 0, 255, u)) return r;
    s.unit = static_cast<std::uint8_t>(u);
    u = 0;
    if (auto r = integer(b, "function", 0, 255, u)) return r;
    s.function = static_cast<std::uint8_t>(u);
    const auto from = b.find("from");
    const bool has_from = from != b.end() && !from->is_null();
    std::uint32_t count = 1;
    if (const auto c = b.find("count"); c != b.end() && has_from) {
        if (auto r = integer(b, "count", 1, kN, count)) return r;
    }
    if (has_from) {
        const std::string name = from->is_string() ? from->get<std::string>() : std::string();
        s.devices = config::comm_fault_range(*plc.naming, name, count);
        if (!s.devices) {
            return error(400, "from: expected a device of this PLC such as R100, got " +
                                  image::excerpt(from->dump(), 40));
        }
    }
    if (const std::string why = plc.faults->refusal(s); !why.empty()) return error(400, why);
    return std::nullopt;
}

}  // namespace

Response comm_faults(const Call& call, const listener::Seat& plc) {
    if (plc.faults == nullptr) return error(404, "this PLC has no communication faults");
    const std::string& m = call.request.method;
    if (m == "DELETE") {
        if (auto r = write_refusal(call, false)) return *r;
        plc.faults->clear();
    } else if (m == "PUT") {
        if (auto r = write_refusal(call)) return *r;
        std::optional<Response> refused;
        const Json body = body_object(call, refused);
        if (refused) return *refused;
        CommFaultSettings s;
        if (auto r = read(body, plc, s)) return *r;
        plc.faults->set(s);
    }
    return json(200, describe(plc));
}

}  // namespace plcemu::http
