#include "http/api.hpp"

#include <boost/beast/core/string.hpp>
#include <algorithm>
#include <charconv>

#include "plcemu/image/excerpt.hpp"

namespace plcemu::http {

Response json(unsigned status, const Json& body) {
    Response r;
    r.status = status;
    // Names and descriptions come from configs: invalid UTF-8 in them is replaced, not fatal.
    r.body = body.dump(-1, ' ', false, Json::error_handler_t::replace);
    r.body += '\n';
    return r;
}

// A refusal quotes what the client sent (a path, a device, a PLC's name): shown by the console
// and by whatever a script prints, it gets the log's escapes (image/excerpt.cpp), so a
// U+202E in an address cannot reorder what the message seems to say, nor a control or a byte
// that is not UTF-8 reach a terminal. The server's own words have none to escape.
Response error(unsigned status, std::string_view why) {
    return json(status, Json{{"error", image::excerpt(why, kMaxErrorChars)}});
}

bool whole_in(const Json& v, long long lo, long long hi) {
    if (v.is_number_unsigned()) {
        const auto u = v.get<unsigned long long>();
        return hi >= 0 && u <= static_cast<unsigned long long>(hi) &&
               (lo <= 0 || u >= static_cast<unsigned long long>(lo));
    }
    if (!v.is_number_integer()) return false;
    const auto x = v.get<long long>();
    return x >= lo && x <= hi;
}

std::string hex2(unsigned v) {
    static constexpr char kDigits[] = "0123456789ABCDEF";
    return {kDigits[(v >> 4) & 0xF], kDigits[v & 0xF]};
}

const listener::Seat* find_plc(listener::UnitTable& units, std::string_view id) {
    const auto& seats = units.seats();
    for (const auto& s : seats) {
        if (s.id == id) return &s;
    }
    // By its position in `plcs:`, for a PLC with a name too.
    if (!id.empty() && id.size() <= 5 &&
        std::all_of(id.begin(), id.end(), [](char c) { return c >= '0' && c <= '9'; })) {
        const std::size_t i = std::stoul(std::string(id));
        for (const auto& s : seats) {
            if (s.position == i) return &s;
        }
    }
    return nullptr;
}

Response no_such_plc(listener::UnitTable& units, std::string_view id) {
    std::string known;
    for (const auto& s : units.seats()) known += (known.empty() ? "" : ", ") + s.id;
    return error(404, "no PLC '" + std::string(id) + "' here (there are: " + known + ")");
}

namespace {

// True for the media type application/json, in any case, with or without parameters
// ("application/json; charset=utf-8"); not "application/jsonx" nor a list of types.
bool is_json(std::string_view content_type) {
    std::string_view t = content_type.substr(0, content_type.find(';'));
    while (!t.empty() && (t.back() == ' ' || t.back() == '\t')) t.remove_suffix(1);
    return boost::beast::iequals(boost::beast::string_view(t.data(), t.size()), "application/json");
}

}  // namespace

std::optional<Response> write_refusal(const Call& call, bool with_body) {
    if (call.units.read_only()) {
        return error(403, "this console is read-only (http.read_only)");
    }
    const std::string& token = call.units.token();
    if (!token.empty()) {
        const std::string& a = call.request.authorization;
        constexpr std::string_view kBearer = "bearer ";
        // The scheme's name is case-insensitive (RFC 9110 §11.1): "Bearer", "bearer".
        const bool bearer =
            a.size() > kBearer.size() &&
            boost::beast::iequals(boost::beast::string_view(a.data(), kBearer.size()),
                                  boost::beast::string_view(kBearer.data(), kBearer.size()));
        if (!bearer) {
            Response r = error(401, "writes need the token: Authorization: Bearer <http.token>");
            r.headers.emplace_back("WWW-Authenticate", "Bearer");
            return r;
        }
        // Compared in time independent of where they differ.
        const std::string_view given = std::string_view(a).substr(kBearer.size());
        unsigned diff = given.size() == token.size() ? 0U : 1U;
        for (std::size_t i = 0; i < token.size(); ++i) {
            diff |=
                static_cast<unsigned>(static_cast<unsigned char>(i < given.size() ? given[i] : 0) ^
                                      static_cast<unsigned char>(token[i]));
        }
        if (diff != 0) {
            Response r = error(401, "wrong token");
            r.headers.emplace_back("WWW-Authenticate", "Bearer error=\"invalid_token\"");
            return r;
        }
    }
    // Only JSON bodies: a cross-origin page can send a form without asking, never JSON.
    if (with_body && !is_json(call.request.content_type)) {
        return error(415, "the body must be JSON (Content-Type: application/json)");
    }
    return std::nullopt;
}

std::size_t count_param(const Call& call,
                        std::size_t absent,
                        std::size_t max,
                        std::optional<Response>& refused) {
    const std::string* c = call.request.param("count");
    if (c == nullptr) return absent;
    std::size_t n = 0;
    const auto [end, ec] = std::from_chars(c->data(), c->data() + c->size(), n);
    if (ec != std::errc() || end != c->data() + c->size() || n == 0 || n > max) {
        refused = error(400, "count: expected 1 to " + std::to_string(max) + ", got '" +
                                 c->substr(0, 20) + "'");
        return absent;
    }
    return n;
}

Json body_object(const Call& call, std::optional<Response>& refused) {
    // No body the API takes nests deeper than a few levels. A deeper one is refused as it is
    // parsed (the parser keeps its own stack): an error message quoting a value calls the
    // library's dump(), which recurses once a level, and 24 KiB of brackets nest 12,000 deep.
    constexpr int kMaxDepth = 32;
    bool deep = false;
    Json j;
    try {
        j = Json::parse(call.request.body, [&deep](int depth, Json::parse_event_t, Json&) {
            if (depth > kMaxDepth) deep = true;
            return !deep;
        });
    } catch (const Json::exception& e) {
        if (deep) {
            refused =
                error(400, "the body nests deeper than " + std::to_string(kMaxDepth) + " levels");
            return {};
        }
        // The parser's own reason (a syntax error and where, a number past a double's range),
        // without its "[json.exception.parse_error.101] " prefix.
        std::string_view why = e.what();
        if (const auto close = why.find("] "); close != std::string_view::npos)
            why.remove_prefix(close + 2);
        std::string message = "the body is not a JSON object (";
        message += why;
        message += ')';
        refused = error(400, message);
        return {};
    }
    if (deep) {
        refused = error(400, "the body nests deeper than " + std::to_string(kMaxDepth) + " levels");
        return {};
    }
    if (j.is_discarded() || !j.is_object()) {
        std::string message = "the body is not a JSON object (it is ";
        message += j.is_array()     ? "an array"
                   : j.is_string()  ? "a string"
                   : j.is_number()  ? "a number"
                   : j.is_boolean() ? "a boolean"
                                    : "null";
        message += ')';
        refused = error(400, message);
        return {};
    }
    return j;
}

}  // namespace plcemu::http
