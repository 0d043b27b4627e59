#include "split.hpp"

#include <algorithm>

#include "frame.hpp"

namespace plcemu::fatek {

listener::Split split_stream(std::span<const std::uint8_t> buffered) noexcept {
    if (buffered.empty()) return {};
    // Skipped bytes are never answered, nor are they a request: a client that sends nothing
    // else is idle, and its connection is closed as an idle one is.
    if (buffered[0] != kStx) {
        // Bytes before an STX: cut off up to it (or all of them).
        const auto stx = std::find(buffered.begin(), buffered.end(), kStx);
        return {listener::Cut::Skip, static_cast<std::size_t>(stx - buffered.begin())};
    }
    const std::size_t look = std::min(buffered.size(), kMaxFrame);
    for (std::size_t i = 1; i < look; ++i) {
        // A new STX abandons the frame begun: what came before it is skipped.
        if (buffered[i] == kStx) return {listener::Cut::Skip, i};
        if (buffered[i] == kEtx) return {listener::Cut::Frame, i + 1};
    }
    // 508 bytes and no ETX: no frame can be that long; they are skipped.
    if (look == kMaxFrame) return {listener::Cut::Skip, kMaxFrame};
    return {};
}

}  // namespace plcemu::fatek
