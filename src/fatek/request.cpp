#include "request.hpp"

#include <algorithm>

#include "checksum.hpp"
#include "frame.hpp"
#include "hex.hpp"

namespace plcemu::fatek {

std::optional<Request> parse_request(std::span<const std::uint8_t> frame) noexcept {
    if (frame.size() < kFrameOverhead || frame.size() > kMaxFrame) return std::nullopt;
    if (frame.front() != kStx || frame.back() != kEtx) return std::nullopt;
    const auto inner = frame.subspan(1, frame.size() - 2);
    if (std::any_of(inner.begin(), inner.end(),
                    [](std::uint8_t b) { return b == kStx || b == kEtx; })) {
        return std::nullopt;
    }
    const auto sum = parse_hex(frame.subspan(frame.size() - 3, 2));
    if (!sum || *sum != checksum(frame.first(frame.size() - 3))) return std::nullopt;
    const auto station = parse_hex(frame.subspan(1, 2));
    if (!station) return std::nullopt;
    Request r;
    r.station = static_cast<std::uint8_t>(*station);
    r.command = frame.subspan(3, 2);
    if (const auto code = parse_hex(r.command)) r.code = static_cast<std::uint8_t>(*code);
    r.data = frame.subspan(kDataAt, frame.size() - kFrameOverhead);
    return r;
}

}  // namespace plcemu::fatek
