#pragma once
// The Modbus limits, in one table shared by the slave's function handlers and the MBUS master
// (Modbus application protocol V1.1b3, 6.1-6.17), and the protocol's byte order.

#include <cstddef>
#include <cstdint>

namespace plcemu::modbus {

/// The largest PDU (function code and data).
inline constexpr std::size_t kMaxPdu = 253;
/// FC 01/02: coils or discrete inputs read at once.
inline constexpr std::uint16_t kMaxReadBits = 2000;
/// FC 03/04: registers read at once.
inline constexpr std::uint16_t kMaxReadRegisters = 125;
/// FC 0Fh: coils written at once.
inline constexpr std::uint16_t kMaxWriteBits = 1968;
/// FC 10h: registers written at once.
inline constexpr std::uint16_t kMaxWriteRegisters = 123;
/// FC 17h: registers read at once.
inline constexpr std::uint16_t kMaxReadWriteRead = 125;
/// FC 17h: registers written at once.
inline constexpr std::uint16_t kMaxReadWriteWrite = 121;
/// The bit a reply's function code carries when it is an exception.
inline constexpr std::uint8_t kExceptionBit = 0x80;

/// Big-endian word at `p`.
inline std::uint16_t be16(const std::uint8_t* p) {
    return static_cast<std::uint16_t>(p[0] << 8 | p[1]);
}
/// Writes `v` big-endian at `p`.
inline void put_be16(std::uint8_t* p, std::uint16_t v) {
    p[0] = static_cast<std::uint8_t>(v >> 8);
    p[1] = static_cast<std::uint8_t>(v & 0xFF);
}

}  // namespace plcemu::modbus
