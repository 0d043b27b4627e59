#include "http/router.hpp"

#include <arpa/inet.h>
#include <netinet/in.h>

#include <boost/beast/core/string.hpp>
#include <algorithm>
#include <array>
#include <string>

#include "http/comm_faults.hpp"
#include "http/console.hpp"
#include "http/devices.hpp"
#include "http/health.hpp"
#include "http/loops.hpp"
#include "http/plcs.hpp"
#include "http/simulator.hpp"
#include "http/traffic.hpp"
#include "plcemu/image/excerpt.hpp"

namespace plcemu::http {

namespace {

Response not_allowed(const char* allow) {
    Response r = error(405, std::string("method not allowed here (allowed: ") + allow + ")");
    r.headers.emplace_back("Allow", allow);
    return r;
}

Response not_found(const Request& rq) {
    return error(404, "nothing at " + image::excerpt(rq.path, 200));
}

// An event stream: every PLC's (`plc` empty) or one PLC's. A HEAD gets the stream's head and no
// subscription, as no events follow it.
Routed events(const Call& call, std::string_view plc) {
    std::optional<Response> refused;
    auto sub = subscribe(call, plc, refused);
    if (refused) return {*refused, {}};
    if (call.request.method == "HEAD") return {event_stream(), {}};
    return {event_stream(), std::move(sub)};
}

// The console's pages: one HTML file each, which fetches what it shows from the API.
Response page(const Call& call, std::string_view name) {
    const Asset* a = find_asset(name);
    if (a == nullptr) return not_found(call.request);
    return asset_response(*a);
}

Routed api(const Call& call) {
    const auto& p = call.parts;  // "api", "v1", ...
    const std::string& m = call.request.method;
    const bool get = m == "GET" || m == "HEAD";
    if (p.size() == 3 && p[2] == "openapi.json") {
        if (!get) return {not_allowed("GET, HEAD"), {}};
        const Asset* a = find_asset("openapi.json");
        Response r = asset_response(*a);
        return {std::move(r), {}};
    }
    if (p.size() == 3 && p[2] == "events") {
        if (!get) return {not_allowed("GET, HEAD"), {}};
        return events(call, "");
    }
    if (p.size() < 3 || p[2] != "plcs") return {not_found(call.request), {}};
    if (p.size() == 3) {
        if (!get) return {not_allowed("GET, HEAD"), {}};
        return {plcs(call), {}};
    }
    const listener::Seat* plc = find_plc(call.units, p[3]);
    if (plc == nullptr) return {no_such_plc(call.units, p[3]), {}};
    if (p.size() == 4) {
        if (!get) return {not_allowed("GET, HEAD"), {}};
        return {json(200, describe(*plc)), {}};
    }
    if (p.size() == 6 && p[4] == "devices") {
        if (!get && m != "PUT") return {not_allowed("GET, HEAD, PUT"), {}};
        return {devices(call, *plc, p[5]), {}};
    }
    if (p.size() == 5 && p[4] == "simulator") {
        if (!get && m != "PUT") return {not_allowed("GET, HEAD, PUT"), {}};
        return {simulator(call, *plc), {}};
    }
    if (p.size() == 5 && p[4] == "comm-faults") {
        if (!get && m != "PUT" && m != "DELETE") return {not_allowed("GET, HEAD, PUT, DELETE"), {}};
        return {comm_faults(call, *plc), {}};
    }
    if (p.size() == 5 && p[4] == "loops") {
        if (!get) return {not_allowed("GET, HEAD"), {}};
        return {loops(call, *plc), {}};
    }
    if (p.size() == 6 && p[4] == "loops" && p[5] == "history") {
        if (!get) return {not_allowed("GET, HEAD"), {}};
        return {loop_history(call, *plc), {}};
    }
    if (p.size() == 5 && p[4] == "traffic") {
        if (!get) return {not_allowed("GET, HEAD"), {}};
        return {traffic(call, *plc), {}};
    }
    if (p.size() == 5 && p[4] == "events") {
        if (!get) return {not_allowed("GET, HEAD"), {}};
        return events(call, p[3]);
    }
    return {not_found(call.request), {}};
}

// Why the Host a request names is not one this console answers to, or "". A page served from
// another name that resolves to this address (DNS rebinding) would be of the same origin as the
// console in the browser: its scripts could read and write. IP addresses, `localhost` and the
// names of `http.hosts` are answered.
std::string foreign_host(const Request& rq, const listener::UnitTable& units) {
    std::string_view h = rq.host;
    if (h.empty()) return "";  // HTTP/1.0: no browser sends a request without one
    // An address is one as the system reads it ("[::1]:8020", "127.0.0.1", "127.1"):
    // "[evil.example]", "999.999.999.999" or "...." are names, and no name but the ones below
    // is answered.
    std::array<unsigned char, 16> address{};
    if (h.front() == '[') {
        if (const auto close = h.find(']'); close != std::string_view::npos) {
            h = h.substr(0, close + 1);  // without its port
            const std::string inside(h.substr(1, close - 1));
            if (::inet_pton(AF_INET6, inside.c_str(), address.data()) == 1) return "";
        }
    } else {
        if (const auto colon = h.rfind(':'); colon != std::string_view::npos) {
            h = h.substr(0, colon);
        }
        // As the system reads an IPv4 address, short and octal forms too (127.1, 0177.0.0.1,
        // as curl sends what it was given): no DNS name is all digits and dots.
        in_addr v4{};
        if (::inet_aton(std::string(h).c_str(), &v4) != 0) return "";
    }
    const boost::beast::string_view host(h.data(), h.size());
    if (boost::beast::iequals(host, "localhost")) return "";
    for (const auto& name : units.hosts()) {
        if (boost::beast::iequals(host, name)) return "";
    }
    return "Host '" + image::excerpt(h, 100) +
           "' is not one this console answers to (its IP address, localhost, or a name in "
           "http.hosts)";
}

}  // namespace

Routed route(const Request& rq, listener::UnitTable& units) {
    if (const std::string why = foreign_host(rq, units); !why.empty()) {
        return {error(421, why), {}};
    }
    const Call call{rq, units, {rq.segments.begin(), rq.segments.end()}};
    const auto& p = call.parts;
    const bool get = rq.method == "GET" || rq.method == "HEAD";
    if (p.size() >= 2 && p[0] == "api" && p[1] == "v1") return api(call);
    if (p.size() == 1 && p[0] == "healthz") {
        if (!get) return {not_allowed("GET, HEAD"), {}};
        return {health(call), {}};
    }
    if (p.size() == 1 && p[0] == "metrics") {
        if (!get) return {not_allowed("GET, HEAD"), {}};
        return {metrics(call), {}};
    }
    if (!get) return {not_allowed("GET, HEAD"), {}};
    if (p.empty()) return {page(call, "overview.html"), {}};
    if (p.size() == 2 && p[0] == "static") return {page(call, p[1]), {}};
    if (p.size() == 3 && p[0] == "plcs") {
        for (std::string_view view : {"devices", "loops", "plant", "traffic"}) {
            if (p[2] != view) continue;
            // An unknown PLC's page is still the page, as a 404: a browser shows it, and the
            // page says what the API says ("no PLC 'zz' here (there are: ...)") as text.
            Response r = page(call, std::string(view) + ".html");
            if (find_plc(units, p[1]) == nullptr) r.status = 404;
            return {std::move(r), {}};
        }
    }
    return {not_found(rq), {}};
}

}  // namespace plcemu::http
