#include "http/health.hpp"

#include "http/loops.hpp"
#include "plcemu/engine/time_control.hpp"

#include <algorithm>
#include <chrono>
#include <cstdint>
#include <optional>
#include <vector>

namespace plcemu::http {

namespace {

// A label value in Prometheus' text format: backslash, double quote and newline escaped.
std::string label(std::string_view v) {
    std::string s;
    for (char c : v) {
        if (c == '\\' || c == '"') {
            s += '\\';
            s += c;
        } else if (c == '\n') {
            s += "\\n";
        } else {
            s += c;
        }
    }
    return s;
}

void help(std::string& out, const char* name, const char* type, const char* text) {
    out += "# HELP ";
    out += name;
    out += ' ';
    out += text;
    out += "\n# TYPE ";
    out += name;
    out += ' ';
    out += type;
    out += '\n';
}

template <typename T>
void sample(std::string& out, const char* name, const std::string& labels, T value) {
    out += name;
    if (!labels.empty()) {
        out += '{';
        out += labels;
        out += '}';
    }
    out += ' ';
    if constexpr (std::is_floating_point_v<T>) {
        out += Json(value).dump();
    } else {
        out += std::to_string(value);
    }
    out += '\n';
}

// A PLC's requests by protocol and function, whatever their outcome.
struct FunctionCount {
    std::uint8_t function;
    std::string_view protocol;
    std::uint64_t count;
};
std::vector<FunctionCount> by_function(const listener::Traffic& traffic) {
    std::vector<FunctionCount> v;
    for (const auto& k : traffic.counts()) {
        auto it = std::find_if(v.begin(), v.end(), [&](const FunctionCount& f) {
            return f.function == k.function && f.protocol == k.protocol;
        });
        if (it == v.end()) {
            v.push_back({k.function, k.protocol, k.count});
        } else {
            it->count += k.count;
        }
    }
    return v;
}

std::string seconds(std::chrono::nanoseconds d) {
    return Json(std::chrono::duration<double>(d).count()).dump();
}

// One histogram of every PLC's scans, in Prometheus' cumulative buckets.
void histogram(std::string& out,
               const std::vector<listener::Seat>& seats,
               const char* name,
               const char* text,
               engine::DurationHistogram engine::ScanFigures::*which) {
    help(out, name, "histogram", text);
    const std::string bucket = std::string(name) + "_bucket";
    for (const auto& s : seats) {
        const auto f = s.time != nullptr ? s.time->scan_figures() : std::nullopt;
        if (!f) continue;
        const engine::DurationHistogram& h = (*f).*which;
        const std::string plc = "plc=\"" + label(s.id) + '"';
        std::uint64_t below = 0;
        for (std::size_t b = 0; b < h.buckets.size(); ++b) {
            below += h.buckets[b];
            std::string le = plc;
            le += ",le=\"";
            le += b < engine::DurationHistogram::kBoundsUs.size()
                      ? seconds(std::chrono::microseconds(engine::DurationHistogram::kBoundsUs[b]))
                      : std::string("+Inf");
            le += '"';
            sample(out, bucket.c_str(), le, below);
        }
        sample(out, (std::string(name) + "_sum").c_str(), plc,
               std::chrono::duration<double>(h.sum).count());
        sample(out, (std::string(name) + "_count").c_str(), plc, h.count);
    }
}

// What the process counts beside its PLCs.
void process(std::string& out, const listener::Census& census) {
    const auto listeners =
        census.connections ? census.connections() : std::vector<listener::ConnectionFigures>{};
    auto each_listener = [&](const char* name, const char* type, const char* text,
                             std::uint64_t listener::ConnectionFigures::*field) {
        help(out, name, type, text);
        for (const auto& l : listeners) {
            std::string labels = "protocol=\"";
            labels += label(l.protocol);
            labels += "\",endpoint=\"";
            labels += label(l.endpoint);
            labels += '"';
            sample(out, name, labels, l.*field);
        }
    };
    each_listener("plcemu_connections_open", "gauge", "TCP connections open, by listener.",
                  &listener::ConnectionFigures::open);
    each_listener("plcemu_connections_accepted_total", "counter",
                  "TCP connections accepted since the listener opened.",
                  &listener::ConnectionFigures::accepted);
    each_listener("plcemu_connections_refused_total", "counter",
                  "TCP connections closed at accept (not in the allow list, or max_clients "
                  "reached) since the listener opened.",
                  &listener::ConnectionFigures::refused);
    help(out, "plcemu_reloads_total", "counter", "SIGHUP reloads since start, by outcome.");
    sample(out, "plcemu_reloads_total", "outcome=\"applied\"", census.reloads_applied);
    sample(out, "plcemu_reloads_total", "outcome=\"rejected\"", census.reloads_rejected);
    help(out, "plcemu_state_syncs_total", "counter",
         "State-file syncs to disk since start, by outcome.");
    sample(out, "plcemu_state_syncs_total", "outcome=\"ok\"",
           census.syncs.load(std::memory_order_relaxed));
    sample(out, "plcemu_state_syncs_total", "outcome=\"failed\"",
           census.sync_failures.load(std::memory_order_relaxed));
    help(out, "plcemu_state_pages_written_total", "counter",
         "State-file pages the syncs wrote to disk since start (a sync writes the pages whose "
         "retentive devices changed).");
    sample(out, "plcemu_state_pages_written_total", "",
           census.pages_synced.load(std::memory_order_relaxed));
}

}  // namespace

Response health(const Call& call) {
    Json plcs = Json::array();
    bool ok = true;
    for (const auto& s : call.units.seats()) {
        const bool scanning = s.time == nullptr || s.time->on_schedule();
        ok = ok && scanning;
        plcs.push_back(Json{{"id", s.id},
                            {"scanning", scanning},
                            {"frozen", s.time != nullptr && s.time->frozen()},
                            {"running", s.engine->running()}});
    }
    return json(ok ? 200 : 503, Json{{"status", ok ? "ok" : "scan behind"}, {"plcs", plcs}});
}

Response metrics(const Call& call) {
    std::string out;
    const auto& seats = call.units.seats();
    auto each = [&](const char* name, const char* type, const char* text, auto value) {
        help(out, name, type, text);
        for (const auto& s : seats) value(s, "plc=\"" + label(s.id) + "\"");
    };
    each("plcemu_scans_total", "counter", "Scans run since the PLC was built (start or reload).",
         [&](const listener::Seat& s, const std::string& l) {
             sample(out, "plcemu_scans_total", l, s.engine->scans());
         });
    each("plcemu_running", "gauge", "1 while the PLC is in RUN, 0 in STOP.",
         [&](const listener::Seat& s, const std::string& l) {
             sample(out, "plcemu_running", l, s.engine->running() ? 1 : 0);
         });
    each("plcemu_frozen", "gauge", "1 while simulated time is frozen.",
         [&](const listener::Seat& s, const std::string& l) {
             sample(out, "plcemu_frozen", l, s.time != nullptr && s.time->frozen() ? 1 : 0);
         });
    each("plcemu_simulated_seconds", "gauge", "Simulated time of the last scan.",
         [&](const listener::Seat& s, const std::string& l) {
             if (s.time == nullptr) return;
             sample(out, "plcemu_simulated_seconds", l,
                    std::chrono::duration<double>(s.time->simulated_time()).count());
         });
    each("plcemu_requests_total", "counter",
         "Requests answered, by protocol and function (Modbus function code, FATEK command "
         "code, as two hex digits), since start.",
         [&](const listener::Seat& s, const std::string& l) {
             if (s.traffic == nullptr) return;
             for (const auto& [function, protocol, count] : by_function(*s.traffic)) {
                 std::string labels = l;
                 labels += ",protocol=\"";
                 labels += protocol;
                 labels += "\",function=\"";
                 labels += hex2(function);
                 labels += '"';
                 sample(out, "plcemu_requests_total", labels, count);
             }
         });
    each("plcemu_request_errors_total", "counter",
         "Requests refused, by protocol, function and the exception (Modbus) or error (FATEK) "
         "code answered, since start.",
         [&](const listener::Seat& s, const std::string& l) {
             if (s.traffic == nullptr) return;
             for (const auto& k : s.traffic->counts()) {
                 if (k.error == 0) continue;
                 std::string labels = l;
                 labels += ",protocol=\"";
                 labels += k.protocol;
                 labels += "\",function=\"";
                 labels += hex2(k.function);
                 labels += "\",code=\"";
                 labels += hex2(k.error);
                 labels += '"';
                 sample(out, "plcemu_request_errors_total", labels, k.count);
             }
         });
    histogram(out, seats, "plcemu_scan_lateness_seconds",
              "How late scans started against their real-time deadlines, since the PLC was "
              "built (start or reload).",
              &engine::ScanFigures::lateness);
    histogram(out, seats, "plcemu_scan_duration_seconds",
              "How long scans took (program, plant and I/O refresh), since the PLC was built.",
              &engine::ScanFigures::duration);
    each("plcemu_plant_temperature_celsius", "gauge",
         "True process temperature of each plant channel.",
         [&](const listener::Seat& s, const std::string& l) {
             if (s.plant == nullptr) return;
             for (int c = 0; c < plant::kChannels; ++c) {
                 sample(out, "plcemu_plant_temperature_celsius",
                        l + ",channel=\"" + std::to_string(c) + "\"", s.plant->true_temperature(c));
             }
         });
    // Per loop: PV and SV in their engineering units, the output in % where it has a scale.
    // Each family's samples stand together, as the text format wants.
    struct Sampled {
        std::string labels;
        std::optional<double> pv;
        double sv = 0;
        std::optional<double> output;
    };
    std::vector<Sampled> loops;
    for (const auto& s : seats) {
        const image::Image& img = s.engine->image();
        auto word = [&](const image::Device& d) {
            return static_cast<double>(static_cast<std::int16_t>(img.read_word(d)));
        };
        for (const engine::Loop& l : engine::loops_of(*s.engine)) {
            Sampled x{"plc=\"" + label(s.id) + "\",loop=\"" + label(l.name) + "\"",
                      {},
                      word(l.sv) * l.scale,
                      {}};
            if (l.pv) x.pv = word(*l.pv) * l.scale;
            if (l.output_full > 0) x.output = 100.0 * word(l.output) / l.output_full;
            loops.push_back(std::move(x));
        }
    }
    help(out, "plcemu_loop_pv", "gauge", "Process value of each control loop of the program.");
    for (const auto& x : loops) {
        if (x.pv) sample(out, "plcemu_loop_pv", x.labels, *x.pv);
    }
    help(out, "plcemu_loop_sv", "gauge", "Set point of each control loop of the program.");
    for (const auto& x : loops) sample(out, "plcemu_loop_sv", x.labels, x.sv);
    help(out, "plcemu_loop_output_percent", "gauge", "Output of each control loop, %.");
    for (const auto& x : loops) {
        if (x.output) sample(out, "plcemu_loop_output_percent", x.labels, *x.output);
    }
    if (const listener::Census* census = call.units.census()) process(out, *census);
    Response r;
    r.content_type = "text/plain; version=0.0.4; charset=utf-8";
    r.body = std::move(out);
    return r;
}

}  // namespace plcemu::http
