#include "http/loops.hpp"

#include <chrono>
#include <cmath>
#include <cstdint>

namespace plcemu::http {

namespace {

// A word's device name: "R100", "WM800".
std::string name_of(const listener::Seat& plc, const image::Device& d) {
    std::string n = d.word_of_bits ? "W" : "";  // appended: see span_names (-Wrestrict)
    n += plc.naming->format_device(d.area, d.index);
    return n;
}

std::int16_t signed_word(const image::Image& img, const image::Device& d) {
    return static_cast<std::int16_t>(img.read_word(d));
}

Json value_json(const listener::Seat& plc, const image::Device& d, double scale) {
    const image::Image& img = plc.engine->image();
    const int raw = signed_word(img, d);
    // Rounded to a millionth: 981 × 0.1 is 98.1, not 98.10000000000001.
    const double value = std::round(raw * scale * 1e6) / 1e6;
    return Json{{"device", name_of(plc, d)}, {"raw", raw}, {"value", value}};
}

Json flag_json(const listener::Seat& plc, const engine::LoopFlag& f) {
    const image::Image& img = plc.engine->image();
    const bool on = image::is_bit_area(f.word.area) && !f.word.word_of_bits
                        ? img.bit(f.word.area, f.word.index)
                        : ((img.read_word(f.word) >> f.bit) & 1U) != 0;
    return Json{{"name", f.name}, {"device", name_of(plc, f.word)}, {"bit", f.bit}, {"on", on}};
}

}  // namespace

Response loops(const Call& /*call*/, const listener::Seat& plc) {
    const image::Image& img = plc.engine->image();
    const engine::Loops found = engine::loops_of(*plc.engine);
    if (plc.history != nullptr) plc.history->watch();
    Json list = Json::array();
    for (const engine::Loop& l : found) {
        Json j{{"name", l.name},
               {"channel", l.channel},
               {"unit", l.unit},
               {"scale", l.scale},
               {"sv", value_json(plc, l.sv, l.scale)},
               {"output", value_json(plc, l.output, 1)},
               {"output_full", l.output_full}};
        j["pv"] = l.pv ? value_json(plc, *l.pv, l.scale) : Json(nullptr);
        if (l.output_full > 0) {
            j["output"]["percent"] = 100.0 * signed_word(img, l.output) / l.output_full;
        }
        Json params = Json::array();
        for (const auto& p : l.parameters) {
            params.push_back(Json{{"name", p.name},
                                  {"device", name_of(plc, p.device)},
                                  {"value", signed_word(img, p.device)},
                                  {"unit", p.unit}});
        }
        j["parameters"] = std::move(params);
        Json alarms = Json::array();
        for (const auto& a : l.alarms) alarms.push_back(flag_json(plc, a));
        j["alarms"] = std::move(alarms);
        j["manual"] = l.manual ? flag_json(plc, *l.manual) : Json(nullptr);
        j["tuning"] = l.tuning ? flag_json(plc, *l.tuning) : Json(nullptr);
        if (plc.plant != nullptr && l.channel >= 0) {
            j["true_temperature_c"] = plc.plant->true_temperature(l.channel);
        }
        list.push_back(std::move(j));
    }
    Json out{{"loops", std::move(list)}};
    if (plc.time != nullptr) {
        out["simulated_s"] = std::chrono::duration<double>(plc.time->simulated_time()).count();
    }
    return json(200, out);
}

Response loop_history(const Call& /*call*/, const listener::Seat& plc) {
    Json list = Json::array();
    if (plc.history != nullptr) {
        plc.history->watch();
        const engine::Loops found = engine::loops_of(*plc.engine);
        // Until its first sample the history has no loops: the program's are listed, empty.
        for (std::size_t i = 0; i < found.size(); ++i) {
            Json samples = Json::array();
            if (plc.history->loops() == found.size()) {
                for (const auto& s : plc.history->samples(i)) {
                    // [t, pv, sv, output]; a PV without a source is null.
                    samples.push_back(Json::array(
                        {s.t, std::isnan(s.pv) ? Json(nullptr) : Json(s.pv), s.sv, s.output}));
                }
            }
            list.push_back(Json{{"name", found[i].name}, {"samples", std::move(samples)}});
        }
    }
    Json out{{"loops", std::move(list)}, {"every_s", 1}};
    if (plc.time != nullptr) {
        out["simulated_s"] = std::chrono::duration<double>(plc.time->simulated_time()).count();
    }
    return json(200, out);
}

}  // namespace plcemu::http
