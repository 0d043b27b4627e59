#include "http/devices.hpp"

#include <utility>
#include <vector>

#include "plcemu/listener/access.hpp"
#include "plcemu/image/excerpt.hpp"

namespace plcemu::http {

namespace {

bool is_bits(const Span& s) { return image::is_bit_area(s.first.area) && !s.first.word_of_bits; }

// Where the span's k-th device lies in its area and how many of the area's entries it takes: a
// `W` span's words are 16 bits apart, and a 32-bit counter's value takes two words (low word
// first), so the counters after one are two words apart.
struct At {
    std::uint32_t index;
    std::uint32_t words;
};

At device_at(const listener::Seat& plc, const Span& s, std::uint32_t k) {
    if (s.first.area == image::Area::CV) {
        const image::Naming& n = *plc.naming;
        const std::uint32_t c = n.counter_of_word(s.first.index) + k;
        return {n.counter_word(c), n.counter_words(c)};
    }
    return {s.first.index + k * (s.first.word_of_bits ? 16 : 1), 1};
}

// The devices a span covers, as an image range (a `W` span: 16 bits a word).
image::Range range_of(const listener::Seat& plc, const Span& s) {
    return plc.naming->devices_from(s.first, s.count);
}

// Why the span may not be written: the protected range it meets ("R4000-R4167 may not be
// written: ..."), or "".
std::string protected_by(const listener::Seat& plc, const Span& s) {
    const auto p =
        listener::write_refused_by(plc.protected_ranges, plc.engine->holds(), range_of(plc, s));
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
    const image::Range r = range_of(plc, s);
    if (r.end() > size) {
        // One device can run past too: WM1990's 16 bits are M1990-M2005.
        std::string what(name);
        if (count > 1) what += " and the " + std::to_string(count - 1) + " after it";
        what += " (";
        what += plc.naming->format_range(r);
        what += count > 1 ? ") go past " : ") goes past ";
        refused = error(400, what + plc.naming->last_of(r.area, size));
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
        const At at = device_at(plc, s, k);
        d.index = at.index;
        if (is_bits(s)) {
            v[k] = img.bit(d.area, d.index) ? 1U : 0U;
            continue;
        }
        v[k] = img.read_word(d);
        if (at.words == 2) v[k] |= std::uint32_t{img.word(d.area, d.index + 1)} << 16;
    }
    return v;
}

Json span_names(const listener::Seat& plc, const Span& s) {
    Json names = Json::array();
    for (std::uint32_t k = 0; k < s.count; ++k) {
        const std::uint32_t i = device_at(plc, s, k).index;
        // Appended, not inserted in front: GCC 12 at -O2 takes insert(0, "W") for an
        // overlapping copy (-Wrestrict, a false positive -Werror would make fatal).
        std::string n = s.first.word_of_bits ? "W" : "";
        n += plc.naming->format_device(s.first.area, i);
        names.push_back(std::move(n));
    }
    return names;
}

Json span_words(const listener::Seat& plc, const Span& s) {
    Json words = Json::array();
    for (std::uint32_t k = 0; k < s.count; ++k) words.push_back(device_at(plc, s, k).words);
    return words;
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
        // Each value with the device it goes to, checked before any is written.
        std::vector<std::pair<At, std::uint32_t>> values;
        values.reserve(s.count);
        const bool bits = is_bits(s);
        for (std::uint32_t k = 0; k < s.count; ++k) {
            const Json& v = (*it)[k];
            const At at = device_at(plc, s, k);
            const bool wide = at.words == 2;
            const long long lo = bits ? 0 : wide ? -2147483648LL : -32768;
            const long long hi = bits ? 1 : wide ? 4294967295LL : 65535;
            long long x = 0;
            if (v.is_boolean()) {
                x = v.get<bool>() ? 1 : 0;
            } else if (!v.is_number_integer()) {
                return error(400,
                             "values: expected whole numbers, got " + image::excerpt(v.dump(), 40));
            } else if (whole_in(v, lo, hi)) {
                x = v.get<long long>();
            } else {
                std::string why = "values: " + v.dump() + " is out of range for ";
                why += plc.naming->format_device(s.first.area, at.index);
                why += bits   ? " (a bit: 0 or 1)"
                       : wide ? " (a 32-bit counter: -2147483648 to 4294967295)"
                              : " (a word: -32768 to 65535)";
                return error(400, why);
            }
            values.emplace_back(at, static_cast<std::uint32_t>(x & 0xFFFFFFFF));
        }
        if (const std::string why = protected_by(plc, s); !why.empty()) return error(403, why);
        image::Image& img = plc.engine->image();
        for (const auto& [at, value] : values) {
            image::Device d = s.first;
            d.index = at.index;
            if (bits) {
                img.set_bit(d.area, d.index, value != 0);
                continue;
            }
            img.write_word(d, static_cast<std::uint16_t>(value & 0xFFFF));
            if (at.words == 2) {
                d.index += 1;
                img.write_word(d, static_cast<std::uint16_t>(value >> 16));
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
                          {"words", span_words(plc, s)},
                          {"values", read_span(plc, s)}});
}

}  // namespace plcemu::http
