#include "split.hpp"

#include <algorithm>

#include "frame.hpp"

namespace plcemu::fatek {

listener::Split split_stream(std::span<const std::uint8_t> buffered) noexcept {
    if (buffered.empty()) return {};
    if (buffered[0] != kStx) {
        // Bytes before an STX: cut off up to it (or all of them), never answered.
        const auto stx = std::find(buffered.begin(), buffered.end(), kStx);
        return {listener::Cut::Frame, static_cast<std::size_t>(stx - buffered.begin())};
    }
    const std::size_t look = std::min(buffered.size(), kMaxFrame);
    for (std::size_t i = 1; i < look; ++i) {
        // A new STX abandons the frame begun: what came before it is skipped.
        if (buffered[i] == kStx) return {listener::Cut::Frame, i};
        if (buffered[i] == kEtx) return {listener::Cut::Frame, i + 1};
    }
    // 508 bytes and no ETX: no frame can be that long; they are skipped.
    if (look == kMaxFrame) return {listener::Cut::Frame, kMaxFrame};
    return {};
}

}  // namespace plcemu::fatek
