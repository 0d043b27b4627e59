#pragma once
// Modbus RTU framing on a whole frame: the address, the PDU between it and the CRC, and how a
// frame is written (address, PDU, CRC low byte first). The one writer of RTU frames, shared by
// the slave side (src/modbus_slave/rtu.cpp) and the MBUS master (rtu_master.cpp); where a frame
// ends on the line is the framer's business (rtu_framer.hpp).

#include <cstddef>
#include <cstdint>
#include <span>

namespace plcemu::modbus {

/// Address, function code, CRC: the shortest frame that carries a PDU.
inline constexpr std::size_t kMinRtuFrame = 4;

/// The address of a whole frame.
inline std::uint8_t rtu_address(std::span<const std::uint8_t> frame) noexcept { return frame[0]; }
/// The PDU of a whole frame (at least kMinRtuFrame bytes): between the address and the CRC.
inline std::span<const std::uint8_t> rtu_pdu(std::span<const std::uint8_t> frame) noexcept {
    return frame.subspan(1, frame.size() - 3);
}

/// Where a frame's PDU goes in `out`, so that it can be written in place and framed by
/// frame_rtu().
inline std::span<std::uint8_t> rtu_pdu_room(std::span<std::uint8_t> out) noexcept {
    return out.subspan(1);
}

/// Frames the `pdu_size` bytes of PDU already at rtu_pdu_room(out): the address before them,
/// the CRC after. Returns the frame's size; 0 when the PDU is empty or the frame would not fit.
std::size_t frame_rtu(std::uint8_t address,
                      std::size_t pdu_size,
                      std::span<std::uint8_t> out) noexcept;

/// Writes the frame for `address` into `out`: the address, `pdu` and the CRC, low byte first.
/// Returns its size; 0 when `pdu` is empty or the frame would not fit.
std::size_t write_rtu(std::uint8_t address,
                      std::span<const std::uint8_t> pdu,
                      std::span<std::uint8_t> out) noexcept;

}  // namespace plcemu::modbus
