#include "http/devices.hpp"

#include "plcemu/listener/access.hpp"
#include "plcemu/image/excerpt.hpp"

namespace plcemu::http {

namespace {

// The devices a span covers, as an image range (a `W` span: 16 bits a word).
image::Range range_of(const Span& s) {
    return {s.first.area, s.first.index, s.first.word_of_bits ? s.count * 16 : s.count};
}

bool is_bits(const Span& s) { return image::is_bit_area(s.first.area) && !s.first.word_of_bits; }

std::uint32_t step_of(const Span& s) { return s.first.word_of_bits ? 16 : 1; }

// Why the span may not be written: the protected range it meets ("R4000-R4167 may not be
// written: ..."), or "".
std::string protected_by(const listener::Seat& plc, const Span& s) {
    const auto p =
        listener::write_refused_by(plc.protected_ranges, plc.engine->holds(), range_of(s));
    if (!p) return "";
    return plc.naming->format_range(*p) +
           " may not be written: the PLC's read-only devices, program data or "
           "modbus.write_protect";
}

}  // namespace

Span parse_span(const listener::Seat& plc,
                std::string_view name,
                std::uint32_t count,
                std::optional<Response>& refused) {
    Span s;
    const auto d = plc.naming->parse_device(name);
    if (!d) {
        std::string why = "no device '" + std::string(name) + "' on a " + plc.profile + " PLC";
        const std::string hint = plc.naming->why_not(name);
        if (!hint.empty()) why += " (" + hint + ")";
        refused = error(404, why);
        return s;
    }
    s.first = *d;
    const image::Layout& layout = plc.engine->image().layout();
    const std::uint32_t size = layout.size_of(s.first.area);
    if (s.first.index >= size) {
        std::string why = "no device '" + std::string(name) + "' on a " + plc.profile + " PLC";
        if (size > 0) {
            why += " (the last " + std::string(plc.naming->area_name(s.first.area)) + " is " +
                   plc.naming->format_device(s.first.area, size - 1) + ")";
        }
        refused = error(404, why);
        return s;
    }
    // Numbers inside an area that no device has (D8000-D8999 on a VB) name no device.
    for (const image::Range& h : layout.holes) {
        if (h.area == s.first.area && s.first.index >= h.start && s.first.index < h.end()) {
            refused = error(404, "no device '" + std::string(name) + "' on a " + plc.profile +
                                     " PLC (" + plc.naming->format_range(h) + " do not exist)");
            return s;
        }
    }
    if (count < 1 || count > kMaxCount) {
        refused = error(400, "count: expected 1 to " + std::to_string(kMaxCount) + ", got " +
                                 std::to_string(count));
        return s;
    }
    s.count = count;
    const image::Range r = range_of(s);
    if (r.end() > size) {
        refused = error(400, std::string(name) + " and the " + std::to_string(count - 1) +
                                 " after it go past the last " +
                                 std::string(plc.naming->area_name(r.area)) + ", " +
                                 plc.naming->format_device(r.area, size - 1));
        return s;
    }
    // A span that runs into such numbers is not read or written either.
    for (const image::Range& h : layout.holes) {
        if (!h.overlaps(r)) continue;
        refused = error(400, std::string(name) + " and the " + std::to_string(count - 1) +
                                 " after it reach " + plc.naming->format_range(h) +
                                 ", which this PLC does not have");
        return s;
    }
    return s;
}

std::vector<std::uint32_t> read_span(const listener::Seat& plc, const Span& s) {
    const image::Image& img = plc.engine->image();
    std::vector<std::uint32_t> v(s.count);
    for (std::uint32_t k = 0; k < s.count; ++k) {
        image::Device d = s.first;
        d.index += k * step_of(s);
        v[k] = is_bits(s) ? (img.bit(d.area, d.index) ? 1U : 0U) : img.read_word(d);
    }
    return v;
}

Json span_names(const listener::Seat& plc, const Span& s) {
    Json names = Json::array();
    for (std::uint32_t k = 0; k < s.count; ++k) {
        const std::uint32_t i = s.first.index + k * step_of(s);
        // Appended, not inserted in front: GCC 12 at -O2 takes insert(0, "W") for an
        // overlapping copy (-Wrestrict, a false positive -Werror would make fatal).
        std::string n = s.first.word_of_bits ? "W" : "";
        n += plc.naming->format_device(s.first.area, i);
        names.push_back(std::move(n));
    }
    return names;
}

Response devices(const Call& call, const listener::Seat& plc, std::string_view device) {
    const Request& rq = call.request;
    std::optional<Response> refused;
    auto count = static_cast<std::uint32_t>(count_param(call, 1, kMaxCount, refused));
    if (refused) return *refused;
    if (rq.method == "PUT") {
        if (auto r = write_refusal(call)) return *r;
        const Json body = body_object(call, refused);
        if (refused) return *refused;
        for (const auto& [k, v] : body.items()) {
            if (k != "values")
                return error(400, image::excerpt(k, 40) + ": unknown key (expected values)");
        }
        const auto it = body.find("values");
        if (it == body.end() || !it->is_array() || it->empty() || it->size() > kMaxCount) {
            std::string why =
                "values: expected a list of 1 to " + std::to_string(kMaxCount) + " numbers";
            if (it != body.end() && it->is_array() && !it->empty())
                why += ", got " + std::to_string(it->size());
            return error(400, why);
        }
        count = static_cast<std::uint32_t>(std::min<std::size_t>(it->size(), kMaxCount + 1));
        const Span s = parse_span(plc, device, count, refused);
        if (refused) return *refused;
        std::vector<std::uint16_t> values;
        values.reserve(s.count);
        const bool bits = is_bits(s);
        for (const Json& v : *it) {
            long long x = 0;
            if (v.is_boolean()) {
                x = v.get<bool>() ? 1 : 0;
            } else if (!v.is_number_integer()) {
                return error(400,
                             "values: expected whole numbers, got " + image::excerpt(v.dump(), 40));
            } else if (whole_in(v, bits ? 0 : -32768, bits ? 1 : 65535)) {
                x = v.get<long long>();
            } else {
                return error(400, "values: " + v.dump() + " is out of range for " +
                                      std::string(device) +
                                      (bits ? " (a bit: 0 or 1)" : " (a word: -32768 to 65535)"));
            }
            values.push_back(static_cast<std::uint16_t>(x & 0xFFFF));
        }
        if (const std::string why = protected_by(plc, s); !why.empty()) return error(403, why);
        image::Image& img = plc.engine->image();
        for (std::uint32_t k = 0; k < s.count; ++k) {
            image::Device d = s.first;
            d.index += k * step_of(s);
            if (is_bits(s)) {
                img.set_bit(d.area, d.index, values[k] != 0);
            } else {
                img.write_word(d, values[k]);
            }
        }
        return json(200, Json{{"device", std::string(device)},
                              {"names", span_names(plc, s)},
                              {"values", read_span(plc, s)}});
    }
    const Span s = parse_span(plc, device, count, refused);
    if (refused) return *refused;
    return json(200, Json{{"device", std::string(device)},
                          {"names", span_names(plc, s)},
                          {"bits", is_bits(s)},
                          {"values", read_span(plc, s)}});
}

}  // namespace plcemu::http
