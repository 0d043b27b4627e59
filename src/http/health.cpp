#include "http/health.hpp"

#include "http/loops.hpp"

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
    out += '{';
    out += labels;
    out += "} ";
    if constexpr (std::is_floating_point_v<T>) {
        out += Json(value).dump();
    } else {
        out += std::to_string(value);
    }
    out += '\n';
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
    each("plcemu_modbus_requests_total", "counter",
         "Modbus requests served, by function code (since the PLC was built).",
         [&](const listener::Seat& s, const std::string& l) {
             if (s.dispatcher == nullptr) return;
             const auto& by = s.dispatcher->stats().by_function;
             for (std::size_t fc = 0; fc < by.size(); ++fc) {
                 if (by[fc] == 0) continue;
                 sample(out, "plcemu_modbus_requests_total",
                        l + ",function=\"" + std::to_string(fc) + "\"", by[fc]);
             }
         });
    each("plcemu_modbus_exceptions_total", "counter",
         "Modbus exception replies, by exception code (since the PLC was built).",
         [&](const listener::Seat& s, const std::string& l) {
             if (s.dispatcher == nullptr) return;
             const auto& by = s.dispatcher->stats().by_exception;
             for (std::size_t code = 0; code < by.size(); ++code) {
                 if (by[code] == 0) continue;
                 sample(out, "plcemu_modbus_exceptions_total",
                        l + ",code=\"" + std::to_string(code) + "\"", by[code]);
             }
         });
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
        for (const engine::Loop& l : loops_of(s)) {
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
    Response r;
    r.content_type = "text/plain; version=0.0.4; charset=utf-8";
    r.body = std::move(out);
    return r;
}

}  // namespace plcemu::http
