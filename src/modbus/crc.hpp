#pragma once
// Modbus RTU CRC-16 (polynomial A001h, initial FFFFh), transmitted low byte first.

#include <cstddef>
#include <cstdint>

namespace plcemu::modbus {

/// CRC of `n` bytes.
std::uint16_t crc16(const std::uint8_t* data, std::size_t n) noexcept;

}  // namespace plcemu::modbus
