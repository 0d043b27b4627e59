#include "http/plcs.hpp"

#include <chrono>
#include <ctime>

namespace plcemu::http {

std::string wall_time(std::chrono::system_clock::time_point t) {
    if (t == std::chrono::system_clock::time_point{}) return "";
    const std::time_t secs = std::chrono::system_clock::to_time_t(t);
    std::tm tm{};
    gmtime_r(&secs, &tm);
    char buf[32];
    const auto ms =
        std::chrono::duration_cast<std::chrono::milliseconds>(t.time_since_epoch()) % 1000;
    const std::size_t n = std::strftime(buf, sizeof buf, "%Y-%m-%dT%H:%M:%S", &tm);
    return std::string(buf, n) + "." + std::to_string(1000 + ms.count()).substr(1) + "Z";
}

Json client_json(const listener::ClientFigures& c) {
    return Json{{"peer", c.peer},
                {"protocol", std::string(c.protocol)},
                {"requests", c.requests},
                {"refusals", c.refusals},
                {"last", wall_time(c.last)}};
}

Json describe(const listener::Seat& plc) {
    const engine::Engine& e = *plc.engine;
    Json j{{"id", plc.id},
           {"index", plc.position},
           {"label", plc.label},
           {"profile", plc.profile},
           {"model", plc.model},
           {"station", plc.station != nullptr ? *plc.station : 0},
           {"listeners", plc.listeners},
           {"scan_ms", plc.scan_ms},
           {"running", e.running()},
           {"scans", e.scans()}};
    Json clients = Json::array();
    if (plc.traffic != nullptr) {
        for (const auto& c : plc.traffic->clients()) clients.push_back(client_json(c));
    }
    j["clients"] = std::move(clients);
    if (plc.time != nullptr) {
        j["lateness_p99_us"] = plc.time->lateness_p99_us();
        j["lateness_max_us"] = plc.time->lateness_max_us();
        // The scan's own time, on average since the PLC was built.
        if (const auto f = plc.time->scan_figures(); f && f->duration.count > 0) {
            j["scan_us"] = std::chrono::duration<double, std::micro>(f->duration.sum).count() /
                           static_cast<double>(f->duration.count);
        }
        j["time"] = Json{
            {"scale", plc.time->time_scale()},
            {"frozen", plc.time->frozen()},
            {"pending_steps", plc.time->pending_steps()},
            {"simulated_s", std::chrono::duration<double>(plc.time->simulated_time()).count()},
        };
    }
    return j;
}

Response plcs(const Call& call) {
    Json list = Json::array();
    const auto& seats = call.units.seats();
    for (const auto& s : seats) list.push_back(describe(s));
    return json(200, Json{{"plcs", std::move(list)}});
}

}  // namespace plcemu::http
