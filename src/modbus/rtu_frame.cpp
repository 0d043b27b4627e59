#include "rtu_frame.hpp"

#include <algorithm>

#include "crc.hpp"
#include "rtu_framer.hpp"

namespace plcemu::modbus {

std::size_t write_rtu(std::uint8_t address,
                      std::span<const std::uint8_t> pdu,
                      std::span<std::uint8_t> out) noexcept {
    const std::size_t n = pdu.size() + 3;
    if (pdu.empty() || n > out.size() || n > RtuFramer::kMaxFrame) return 0;
    out[0] = address;
    std::copy(pdu.begin(), pdu.end(), out.begin() + 1);
    const std::uint16_t crc = crc16(out.data(), n - 2);
    out[n - 2] = static_cast<std::uint8_t>(crc & 0xFF);
    out[n - 1] = static_cast<std::uint8_t>(crc >> 8);
    return n;
}

}  // namespace plcemu::modbus
