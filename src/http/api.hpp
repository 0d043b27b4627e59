#pragma once
// What every handler of the HTTP side takes and gives: the request, the PLCs of the listener
// (its unit table, which also holds its `read_only` and `token`), and JSON answers. The handlers
// are views of the PLCs' operations (DESIGN principle 16): none keeps state of its own.

#include <nlohmann/json.hpp>
#include <cstddef>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "http/message.hpp"
#include "plcemu/listener/unit_table.hpp"

namespace plcemu::http {

using Json = nlohmann::json;

/// A request with what it reaches.
struct Call {
    const Request& request;
    listener::UnitTable& units;
    std::vector<std::string_view> parts;  ///< the path's segments: {"api", "v1", "plcs", "0"}
};

/// A JSON answer.
Response json(unsigned status, const Json& body);
/// Longest refusal, in characters (a longer one is cut, with "…").
inline constexpr std::size_t kMaxErrorChars = 1000;
/// `{"error": why}` with a 4xx status; controls, bidirectional marks and bytes that are not
/// UTF-8 in `why` escaped as the log escapes them (`\u202E`, `\x01`).
Response error(unsigned status, std::string_view why);

/// True when `v` is a JSON integer from `lo` to `hi`. One above 2^63 is kept by the JSON library
/// as unsigned, and get<long long>() wraps it (2^64 - 1 is -1): every number of a body is read
/// through this.
bool whole_in(const Json& v, long long lo, long long hi);

/// The PLC `id` names: its `name:`, or its position ("0", "1", ...); null when none.
const listener::Seat* find_plc(listener::UnitTable& units, std::string_view id);
/// The answer for an unknown PLC: 404 naming the PLCs there are.
Response no_such_plc(listener::UnitTable& units, std::string_view id);

/// A code as two hex digits ("0B"), as the traffic and the metrics write function, command,
/// exception and error codes.
std::string hex2(unsigned v);

/// Why a write may not be made through this listener (read_only, a missing or wrong bearer
/// token, a body that is not JSON), as the answer to give; nothing when it may. A write
/// without a body (`DELETE`: a method a cross-origin page cannot send without asking) is not
/// asked for JSON.
std::optional<Response> write_refusal(const Call& call, bool with_body = true);

/// The request's `count` parameter: `absent` without one; 1 to `max`, else `refused` is set
/// (400 naming the range and what was given).
std::size_t count_param(const Call& call,
                        std::size_t absent,
                        std::size_t max,
                        std::optional<Response>& refused);

/// The body of a write, parsed; sets `refused` when it is not a JSON object.
Json body_object(const Call& call, std::optional<Response>& refused);

}  // namespace plcemu::http
