#pragma once
// A FATEK request frame taken apart, or nothing when it is to be dropped without a reply
// (docs/profile-fbs.md, "FATEK protocol", framing): shorter than 8 or longer than 508 bytes, not
// STX ... ETX, an STX or ETX inside, a station or checksum that is not hex, a wrong checksum.

#include <cstdint>
#include <optional>
#include <span>

namespace plcemu::fatek {

/// A request that arrived whole.
struct Request {
    std::uint8_t station = 0;               ///< the station it is for (0: every PLC)
    std::span<const std::uint8_t> command;  ///< its two command characters, as received
    std::optional<std::uint8_t> code;       ///< the command code, when those are hex
    std::span<const std::uint8_t> data;     ///< the data characters
};

/// The request `frame` holds, or nothing.
std::optional<Request> parse_request(std::span<const std::uint8_t> frame) noexcept;

}  // namespace plcemu::fatek
