#include "rtu_frame.hpp"

#include <algorithm>

#include "crc.hpp"
#include "rtu_framer.hpp"

namespace plcemu::modbus {

std::size_t frame_rtu(std::uint8_t address,
                      std::size_t pdu_size,
                      std::span<std::uint8_t> out) noexcept {
    const std::size_t n = pdu_size + 3;
    if (pdu_size == 0 || n > out.size() || n > RtuFramer::kMaxFrame) return 0;
    out[0] = address;
    const std::uint16_t crc = crc16(out.data(), n - 2);
    out[n - 2] = static_cast<std::uint8_t>(crc & 0xFF);
    out[n - 1] = static_cast<std::uint8_t>(crc >> 8);
    return n;
}

std::size_t write_rtu(std::uint8_t address,
                      std::span<const std::uint8_t> pdu,
                      std::span<std::uint8_t> out) noexcept {
    const std::size_t n = pdu.size() + 3;
    if (pdu.empty() || n > out.size() || n > RtuFramer::kMaxFrame) return 0;
    std::copy(pdu.begin(), pdu.end(), rtu_pdu_room(out).begin());
    return frame_rtu(address, pdu.size(), out);
}

}  // namespace plcemu::modbus
