#include "mbap.hpp"

namespace plcemu::modbus {

MbapFrame next_mbap_frame(std::span<const std::uint8_t> buffered) noexcept {
    MbapFrame f;
    if (buffered.size() < kMbapPrefix + 1) return f;
    f.protocol = static_cast<std::uint16_t>(buffered[2] << 8 | buffered[3]);
    f.length = static_cast<std::uint16_t>(buffered[4] << 8 | buffered[5]);
    // Length counts the unit ID and the PDU: at least a function code, at most 253 PDU bytes.
    if (f.protocol != 0 || f.length < 2 || f.length > kMaxTcpAdu - kMbapPrefix) {
        f.status = MbapStatus::Bad;
        return f;
    }
    const std::size_t total = kMbapPrefix + f.length;
    if (buffered.size() < total) return f;
    f.status = MbapStatus::Frame;
    f.size = total;
    return f;
}

}  // namespace plcemu::modbus
