#include "checksum.hpp"

#include <cstring>

namespace plcemu::fatek {

std::uint8_t checksum(std::span<const std::uint8_t> bytes) noexcept {
    // Eight bytes at a time, each lane summed modulo 256 on its own (no carry crosses a lane):
    // a 64-register reply is 265 bytes, and the byte loop was a third of its time.
    constexpr std::uint64_t kLow7 = 0x7F7F7F7F7F7F7F7FULL;
    constexpr std::uint64_t kHigh = 0x8080808080808080ULL;
    std::uint64_t lanes = 0;
    std::size_t i = 0;
    for (; i + 8 <= bytes.size(); i += 8) {
        std::uint64_t w;
        std::memcpy(&w, bytes.data() + i, 8);
        lanes = ((lanes & kLow7) + (w & kLow7)) ^ ((lanes ^ w) & kHigh);
    }
    std::uint8_t sum = 0;
    for (int k = 0; k < 8; ++k) sum = static_cast<std::uint8_t>(sum + (lanes >> (8 * k)));
    for (; i < bytes.size(); ++i) sum = static_cast<std::uint8_t>(sum + bytes[i]);
    return sum;
}

}  // namespace plcemu::fatek
