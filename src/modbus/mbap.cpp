#include "mbap.hpp"

#include <algorithm>

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

std::size_t frame_mbap(std::uint16_t transaction,
                       std::uint8_t unit,
                       std::size_t pdu_size,
                       std::span<std::uint8_t> out) noexcept {
    const std::size_t n = kMbapPrefix + 1 + pdu_size;
    if (pdu_size == 0 || n > out.size() || n > kMaxTcpAdu) return 0;
    const auto length = static_cast<std::uint16_t>(pdu_size + 1);
    out[0] = static_cast<std::uint8_t>(transaction >> 8);
    out[1] = static_cast<std::uint8_t>(transaction & 0xFF);
    out[2] = 0;
    out[3] = 0;
    out[4] = static_cast<std::uint8_t>(length >> 8);
    out[5] = static_cast<std::uint8_t>(length & 0xFF);
    out[kMbapPrefix] = unit;
    return n;
}

std::size_t write_mbap(std::uint16_t transaction,
                       std::uint8_t unit,
                       std::span<const std::uint8_t> pdu,
                       std::span<std::uint8_t> out) noexcept {
    const std::size_t n = kMbapPrefix + 1 + pdu.size();
    if (pdu.empty() || n > out.size() || n > kMaxTcpAdu) return 0;
    std::copy(pdu.begin(), pdu.end(), mbap_pdu_room(out).begin());
    return frame_mbap(transaction, unit, pdu.size(), out);
}

}  // namespace plcemu::modbus
