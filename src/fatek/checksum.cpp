#include "checksum.hpp"

namespace plcemu::fatek {

std::uint8_t checksum(std::span<const std::uint8_t> bytes) noexcept {
    unsigned sum = 0;
    for (const std::uint8_t b : bytes) sum += b;
    return static_cast<std::uint8_t>(sum & 0xFF);
}

}  // namespace plcemu::fatek
