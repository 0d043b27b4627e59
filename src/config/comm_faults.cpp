#include "plcemu/config/comm_faults.hpp"

#include "config/comm_fault_section.hpp"

#include <cmath>
#include <cstdio>

#include "plcemu/image/excerpt.hpp"

namespace plcemu::config {

bool CommFaultSettings::any() const {
    return delay_max_ms > 0 || drop_every > 0 || drop_probability > 0 || exception != 0 ||
           offline || refuse_connections || disconnect_after.has_value() ||
           garble != Garble::None || stop;
}

std::string comm_fault_refusal(const CommFaultSettings& s) {
    if (s.delay_min_ms > s.delay_max_ms)
        return "delay_ms: expected [min, max] with min at most max";
    if (s.delay_max_ms > kMaxCommDelayMs)
        return "delay_ms: expected 0 to " + std::to_string(kMaxCommDelayMs) + " ms";
    if (s.drop_every > kMaxCommCount)
        return "drop_every: expected 0 to " + std::to_string(kMaxCommCount);
    if (!(s.drop_probability >= 0 && s.drop_probability <= 1))
        return "drop_probability: expected a number from 0 to 1";
    if (s.drop_every > 0 && s.drop_probability > 0)
        return "drop_probability: drop_every is set too; expected one of them, not both";
    if (s.disconnect_after && *s.disconnect_after > kMaxCommCount)
        return "disconnect_after: expected 0 to " + std::to_string(kMaxCommCount);
    if (s.reset && !s.disconnect_after)
        return "reset: says how disconnect_after closes; expected disconnect_after beside it";
    if (s.devices && (s.devices->count == 0 || s.devices->count > kMaxCommCount * 16))
        return "count: expected 1 to " + std::to_string(kMaxCommCount);
    return {};
}

std::optional<image::Range> comm_fault_range(const image::Naming& naming,
                                             std::string_view from,
                                             std::uint32_t count) {
    if (count == 0 || count > kMaxCommCount) return std::nullopt;
    const auto d = naming.parse_device(from);
    if (!d) return std::nullopt;
    // WM800 with count 2: the 32 bits M800-M831; CTR200 with count 2 two 32-bit counters, four
    // words: devices as the devices API counts them.
    return naming.devices_from(*d, count);
}

std::string_view garble_name(Garble g) {
    switch (g) {
        case Garble::Crc:
            return "crc";
        case Garble::Short:
            return "short";
        case Garble::Gap:
            return "gap";
        case Garble::None:
            break;
    }
    return "none";
}

std::optional<Garble> garble_named(std::string_view name) {
    for (const Garble g : {Garble::None, Garble::Crc, Garble::Short, Garble::Gap}) {
        if (garble_name(g) == name) return g;
    }
    return std::nullopt;
}

namespace {

std::string hex2(unsigned v) {
    char b[8];
    std::snprintf(b, sizeof b, "%02X", v & 0xFFu);
    return b;
}

std::string ordinal(std::uint32_t n) {
    const std::uint32_t tens = n % 100;
    const char* suffix = "th";
    if (tens < 11 || tens > 13) {
        if (n % 10 == 1) suffix = "st";
        if (n % 10 == 2) suffix = "nd";
        if (n % 10 == 3) suffix = "rd";
    }
    return std::to_string(n) + suffix;
}

}  // namespace

std::vector<std::string> comm_fault_lines(const CommFaultSettings& s) {
    std::vector<std::string> v;
    if (s.delay_max_ms > 0) {
        v.push_back(s.delay_min_ms == s.delay_max_ms
                        ? "delay " + std::to_string(s.delay_max_ms) + " ms"
                        : "delay " + std::to_string(s.delay_min_ms) + "-" +
                              std::to_string(s.delay_max_ms) + " ms (seed " +
                              std::to_string(s.seed) + ")");
    }
    if (s.drop_every == 1) v.emplace_back("drop every request");
    if (s.drop_every > 1) v.push_back("drop every " + ordinal(s.drop_every) + " request");
    if (s.drop_probability > 0) {
        char b[64];
        std::snprintf(b, sizeof b, "drop with probability %g (seed %u)", s.drop_probability,
                      static_cast<unsigned>(s.seed));
        v.emplace_back(b);
    }
    if (s.exception != 0) v.push_back("exception " + hex2(s.exception) + "h");
    if (s.offline) v.emplace_back("offline");
    if (s.refuse_connections) v.emplace_back("refuse connections");
    if (s.disconnect_after) {
        const std::string how = s.reset ? " (reset)" : " (FIN)";
        v.push_back(*s.disconnect_after == 0
                        ? "disconnect at once" + how
                        : "disconnect after " + std::to_string(*s.disconnect_after) +
                              " request(s)" + how);
    }
    if (s.garble != Garble::None) v.push_back("garble " + std::string(garble_name(s.garble)));
    if (s.stop) v.emplace_back("stop");
    return v;
}

std::string comm_fault_scope(const CommFaultSettings& s, const image::Naming& naming) {
    std::string out;
    const auto add = [&](const std::string& part) { out += (out.empty() ? "" : ", ") + part; };
    if (s.unit != 0) add("unit " + std::to_string(s.unit));
    if (s.function != 0) add("function " + hex2(s.function) + "h");
    if (s.devices) add(naming.format_range(*s.devices));
    return out.empty() ? "every request" : out;
}

void read_comm_faults(const Reader& r, const Node& f, CommFaultSettings& s) {
    r.check_keys(f, "faults",
                 {"delay_ms", "drop_every", "drop_probability", "seed", "exception", "offline",
                  "refuse_connections", "disconnect_after", "reset", "garble", "stop", "unit",
                  "function", "from", "count"});
    const auto ms = [&](const Node& n) {
        return static_cast<std::uint32_t>(r.integer(n, "faults.delay_ms", 0, kMaxCommDelayMs));
    };
    if (const Node& d = f["delay_ms"]) {
        if (d.is_sequence()) {
            if (d.size() != 2) r.fail(d, "faults.delay_ms: expected a number of ms or [min, max]");
            s.delay_min_ms = ms(d.items[0]);
            s.delay_max_ms = ms(d.items[1]);
        } else {
            s.delay_min_ms = s.delay_max_ms = ms(d);
        }
    }
    const auto count = [&](const char* key, std::uint32_t lo) {
        return static_cast<std::uint32_t>(
            r.integer(f[key], std::string("faults.") + key, lo, kMaxCommCount));
    };
    if (f["drop_every"]) s.drop_every = count("drop_every", 0);
    if (f["drop_probability"])
        s.drop_probability = r.number(f["drop_probability"], "faults.drop_probability", 0, 1);
    if (f["seed"])
        s.seed = static_cast<std::uint32_t>(r.integer(f["seed"], "faults.seed", 0, 0xFFFFFFFFLL));
    if (f["exception"])
        s.exception =
            static_cast<std::uint8_t>(r.integer(f["exception"], "faults.exception", 0, 255));
    if (f["offline"]) s.offline = r.boolean(f["offline"], "faults.offline");
    if (f["refuse_connections"])
        s.refuse_connections = r.boolean(f["refuse_connections"], "faults.refuse_connections");
    if (f["disconnect_after"]) s.disconnect_after = count("disconnect_after", 0);
    if (f["reset"]) s.reset = r.boolean(f["reset"], "faults.reset");
    if (const Node& g = f["garble"]) {
        const auto kind = garble_named(r.scalar(g, "faults.garble"));
        if (!kind) r.fail(g, "faults.garble: expected crc, short, gap or none");
        s.garble = *kind;
    }
    if (f["stop"]) s.stop = r.boolean(f["stop"], "faults.stop");
    if (f["unit"]) s.unit = static_cast<std::uint8_t>(r.integer(f["unit"], "faults.unit", 0, 255));
    if (f["function"])
        s.function = static_cast<std::uint8_t>(r.integer(f["function"], "faults.function", 0, 255));
    if (f["count"] && !f["from"])
        r.fail(f["count"], "faults.count: counts devices from `from`; expected from beside it");
    if (const Node& from = f["from"]) {
        const std::string name = r.scalar(from, "faults.from");
        const std::uint32_t n = f["count"] ? count("count", 1) : 1;
        s.devices = comm_fault_range(r.naming(), name, n);
        if (!s.devices) {
            const std::string hint = r.naming().why_not(name);
            r.fail(from, "faults.from: expected a device such as R100, got '" +
                             image::excerpt(name) + "'" + (hint.empty() ? "" : " (" + hint + ")"));
        }
    }
    // The rules every view shares (comm_fault_refusal), at the key its message starts with.
    if (const std::string why = comm_fault_refusal(s); !why.empty()) {
        const Node& at = f[why.substr(0, why.find(':'))];
        r.fail(at ? at : f, "faults." + why);
    }
}

}  // namespace plcemu::config
