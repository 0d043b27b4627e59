#include "http/events.hpp"

#include "http/devices.hpp"
#include "http/plcs.hpp"

namespace plcemu::http {

namespace {

using Clock = std::chrono::steady_clock;

// PLC states go out once a second; a comment keeps a quiet stream alive through proxies.
constexpr auto kStatePeriod = std::chrono::seconds(1);
constexpr auto kKeepAlive = std::chrono::seconds(15);

void event(std::string& out, const char* name, const Json& data) {
    out += "event: ";
    out += name;
    out += "\ndata: ";
    out += data.dump(-1, ' ', false, Json::error_handler_t::replace);
    out += "\n\n";
}

}  // namespace

Subscription::Subscription(std::string plc, std::string device, std::uint32_t count)
    : plc_(std::move(plc)),
      device_(std::move(device)),
      count_(count) {}

std::string Subscription::poll(listener::UnitTable& units, bool& ended) {
    std::string out;
    const auto now = Clock::now();
    const listener::Seat* plc = plc_.empty() ? nullptr : find_plc(units, plc_);
    if (!plc_.empty() && plc == nullptr) {
        event(out, "gone", Json{{"error", "PLC '" + plc_ + "' is gone (reloaded without it)"}});
        ended = true;
        return out;
    }
    if (now - last_state_ >= kStatePeriod) {
        last_state_ = now;
        Json list = Json::array();
        for (const auto& s : units.seats()) {
            if (plc == nullptr || &s == plc) list.push_back(describe(s));
        }
        event(out, "plcs", Json{{"plcs", std::move(list)}});
    }
    if (plc != nullptr && !device_.empty()) {
        std::optional<Response> refused;
        const Span s = parse_span(*plc, device_, count_, refused);
        if (refused) {
            event(out, "gone", Json{{"error", "device " + device_ + " is gone"}});
            ended = true;
            return out;
        }
        std::vector<std::uint32_t> values = read_span(*plc, s);
        if (!sent_values_ || values != last_values_) {
            event(out, "values",
                  Json{{"device", device_},
                       {"names", span_names(*plc, s)},
                       {"words", span_words(*plc, s)},
                       {"values", values}});
            last_values_ = std::move(values);
            sent_values_ = true;
        }
    }
    if (out.empty() && now - last_sent_ >= kKeepAlive) out = ": keep-alive\n\n";
    if (!out.empty()) last_sent_ = now;
    return out;
}

std::optional<Subscription> subscribe(const Call& call,
                                      std::string_view plc,
                                      std::optional<Response>& refused) {
    std::string id;
    std::string device;
    std::uint32_t count = 1;
    if (!plc.empty()) {
        const listener::Seat* seat = find_plc(call.units, plc);
        if (seat == nullptr) {
            refused = no_such_plc(call.units, plc);
            return std::nullopt;
        }
        id = seat->id;
        count = static_cast<std::uint32_t>(count_param(call, 1, kMaxCount, refused));
        if (refused) return std::nullopt;
        if (const std::string* d = call.request.param("device")) {
            device = *d;
            parse_span(*seat, device, count, refused);
            if (refused) return std::nullopt;
        }
    }
    return Subscription(std::move(id), std::move(device), count);
}

}  // namespace plcemu::http
