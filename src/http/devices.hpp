#pragma once
// Devices by the family's names (`R100`, `WM800`, `X17` in octal on a VB): read, written through
// the same checks as a write from a master, and described for the console.

#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "http/api.hpp"
#include "plcemu/image/area.hpp"

namespace plcemu::http {

/// Devices from one, by name.
struct Span {
    image::Device first;      ///< the first device
    std::uint32_t count = 1;  ///< how many
};

/// Largest count of one read or write.
inline constexpr std::uint32_t kMaxCount = 1000;

/// Reads "R100" with `count` against the PLC's names and sizes; sets `refused` (404 for a name
/// the family does not have, 400 for a count out of range) when it is not a span.
Span parse_span(const listener::Seat& plc,
                std::string_view name,
                std::uint32_t count,
                std::optional<Response>& refused);

/// The span's values: 0/1 for bits, 0–65535 for words (16 bits of a `W` span), 0–4294967295
/// for 32-bit counters (both words, low word first).
std::vector<std::uint32_t> read_span(const listener::Seat& plc, const Span& span);

/// The span's device names ("R100", "R101", ...; "WM800", "WM816" for words of bits).
Json span_names(const listener::Seat& plc, const Span& span);

/// The words each of the span's devices takes: 2 for a 32-bit counter, else 1.
Json span_words(const listener::Seat& plc, const Span& span);

/// `GET/PUT /api/v1/plcs/{plc}/devices/{device}`.
Response devices(const Call& call, const listener::Seat& plc, std::string_view device);

}  // namespace plcemu::http
