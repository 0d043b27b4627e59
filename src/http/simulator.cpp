#include "http/simulator.hpp"
#include "plcemu/image/excerpt.hpp"

#include <chrono>

namespace plcemu::http {

namespace {

// The simulator unit's ranges (docs/simulator-and-plant.md, "Simulator-control unit").
constexpr double kMinScale = 1;
constexpr double kMaxScale = 10000;
constexpr std::uint64_t kMaxStep = 65535;

Json faults_json(const plant::Faults& f) {
    return Json{{"sensor_broken", f.sensor_broken},
                {"heater_open", f.heater_open},
                {"heater_shorted", f.heater_shorted},
                {"reading_frozen", f.reading_frozen}};
}

Json state(const listener::Seat& plc) {
    Json channels = Json::array();
    for (int c = 0; c < plant::kChannels; ++c) {
        const plant::ChannelParams& p = plc.plant->params(c);
        channels.push_back(Json{{"channel", c},
                                {"true_temperature_c", plc.plant->true_temperature(c)},
                                {"heater_power", plc.plant->heater_power(c)},
                                {"ambient_c", p.ambient_c},
                                {"k_c", p.k_c},
                                {"tau_s", p.tau_s},
                                {"dead_time_s", p.dead_time_s},
                                {"noise_c", p.noise_c},
                                {"faults", faults_json(plc.plant->faults(c))}});
    }
    return Json{{"time_scale", plc.time->time_scale()},
                {"frozen", plc.time->frozen()},
                {"pending_steps", plc.time->pending_steps()},
                {"simulated_s", std::chrono::duration<double>(plc.time->simulated_time()).count()},
                {"channels", std::move(channels)}};
}

// A number in [lo, hi] at `key` of `o`, or a refusal.
bool number(const Json& o,
            const char* key,
            double lo,
            double hi,
            double& out,
            std::optional<Response>& refused) {
    const auto it = o.find(key);
    if (it == o.end()) return false;
    if (!it->is_number() || it->get<double>() < lo || it->get<double>() > hi) {
        refused = error(400, std::string(key) + ": expected a number from " + Json(lo).dump() +
                                 " to " + Json(hi).dump());
        return false;
    }
    out = it->get<double>();
    return true;
}

// Checks and applies a channel's changes; nothing applied when one is refused.
std::optional<Response> channel_changes(const listener::Seat& plc, const Json& list) {
    if (!list.is_array()) return error(400, "channels: expected a list of channel objects");
    struct Change {
        int channel;
        plant::ChannelParams params;
        plant::Faults faults;
    };
    std::vector<Change> changes;
    for (const Json& ch : list) {
        if (!ch.is_object()) return error(400, "channels: expected a list of channel objects");
        const auto c = ch.find("channel");
        if (c == ch.end() || !whole_in(*c, 0, plant::kChannels - 1)) {
            return error(
                400, "channels[].channel: expected 0 to " + std::to_string(plant::kChannels - 1));
        }
        for (const auto& [k, v] : ch.items()) {
            static const std::vector<std::string> known{
                "channel", "ambient_c", "k_c", "tau_s", "dead_time_s", "noise_c", "faults"};
            if (std::find(known.begin(), known.end(), k) == known.end()) {
                return error(400, "channels[]." + image::excerpt(k, 40) +
                                      ": unknown key (expected one of channel, ambient_c, k_c, "
                                      "tau_s, dead_time_s, noise_c, faults)");
            }
        }
        Change x{static_cast<int>(c->get<long long>()), {}, {}};
        x.params = plc.plant->params(x.channel);
        x.faults = plc.plant->faults(x.channel);
        std::optional<Response> refused;
        // The simulator unit's ranges (docs/simulator-and-plant.md).
        number(ch, "ambient_c", -200, 1000, x.params.ambient_c, refused);
        number(ch, "k_c", 0, 3000, x.params.k_c, refused);
        number(ch, "tau_s", 0.1, 100000, x.params.tau_s, refused);
        number(ch, "dead_time_s", 0, 3600, x.params.dead_time_s, refused);
        number(ch, "noise_c", 0, 100, x.params.noise_c, refused);
        if (refused) return refused;
        if (const auto f = ch.find("faults"); f != ch.end()) {
            if (!f->is_object()) return error(400, "faults: expected an object of switches");
            for (const auto& [k, v] : f->items()) {
                if (!v.is_boolean())
                    return error(400,
                                 "faults." + image::excerpt(k, 40) + ": expected true or false");
                const bool on = v.get<bool>();
                if (k == "sensor_broken") {
                    x.faults.sensor_broken = on;
                } else if (k == "heater_open") {
                    x.faults.heater_open = on;
                } else if (k == "heater_shorted") {
                    x.faults.heater_shorted = on;
                } else if (k == "reading_frozen") {
                    x.faults.reading_frozen = on;
                } else {
                    return error(400, "faults." + image::excerpt(k, 40) +
                                          ": unknown fault (expected sensor_broken, heater_open, "
                                          "heater_shorted or reading_frozen)");
                }
            }
        }
        changes.push_back(x);
    }
    for (const Change& x : changes) {
        plc.plant->set_params(x.channel, x.params);
        plc.plant->set_faults(x.channel, x.faults);
    }
    return std::nullopt;
}

}  // namespace

Response simulator(const Call& call, const listener::Seat& plc) {
    if (plc.time == nullptr || plc.plant == nullptr) {
        return error(404, "this PLC has no simulator");
    }
    if (call.request.method == "PUT") {
        if (auto r = write_refusal(call)) return *r;
        std::optional<Response> refused;
        const Json body = body_object(call, refused);
        if (refused) return *refused;
        for (const auto& [k, v] : body.items()) {
            if (k != "time_scale" && k != "frozen" && k != "step" && k != "channels") {
                return error(400,
                             image::excerpt(k, 40) +
                                 ": unknown key (expected time_scale, frozen, step or channels)");
            }
        }
        double scale = 0;
        const bool has_scale = number(body, "time_scale", kMinScale, kMaxScale, scale, refused);
        if (refused) return *refused;
        const auto frozen = body.find("frozen");
        if (frozen != body.end() && !frozen->is_boolean()) {
            return error(400, "frozen: expected true or false");
        }
        const auto step = body.find("step");
        if (step != body.end() && !whole_in(*step, 0, static_cast<long long>(kMaxStep))) {
            return error(400,
                         "step: expected a number of scans from 0 to " + std::to_string(kMaxStep));
        }
        // Channels first: they are the only part that can still be refused.
        if (const auto ch = body.find("channels"); ch != body.end()) {
            if (auto r = channel_changes(plc, *ch)) return *r;
        }
        if (has_scale) plc.time->set_time_scale(scale);
        if (frozen != body.end()) plc.time->set_frozen(frozen->get<bool>());
        if (step != body.end() && step->get<long long>() > 0) {
            plc.time->step(static_cast<std::uint64_t>(step->get<long long>()));
        }
    }
    return json(200, state(plc));
}

}  // namespace plcemu::http
