#pragma once
// Modbus TCP framing (MBAP): where the next frame of a byte stream ends, what a whole frame
// holds, and how one is written. The one writer and reader of MBAP headers, shared by the slave
// side (src/modbus_slave/tcp.cpp), the MBUS master (tcp_master.cpp) and the fuzz harnesses.

#include <cstddef>
#include <cstdint>
#include <span>

namespace plcemu::modbus {

/// Bytes of the MBAP header before the unit ID: transaction, protocol, length.
inline constexpr std::size_t kMbapPrefix = 6;
/// Largest Modbus TCP ADU (MBAP header + 253-byte PDU).
inline constexpr std::size_t kMaxTcpAdu = 260;

/// What the head of a TCP byte stream holds.
enum class MbapStatus : std::uint8_t {
    Incomplete,  ///< not a whole frame yet: wait for more bytes
    Frame,       ///< a whole frame of `size` bytes
    Bad,         ///< a bad header closes the connection (docs/profile-fbs.md, "Modbus map")
};

/// The next frame of a stream.
struct MbapFrame {
    MbapStatus status = MbapStatus::Incomplete;  ///< what was found
    std::size_t size = 0;                        ///< bytes of the frame (Frame only)
    std::uint16_t protocol = 0;                  ///< protocol identifier (once the header is in)
    std::uint16_t length = 0;                    ///< length field (once the header is in)
};

/// Looks at the bytes received and not yet served. The header is judged once the unit ID is in
/// (7 bytes): protocol identifier 0 and a length field of 2..254, else Bad.
MbapFrame next_mbap_frame(std::span<const std::uint8_t> buffered) noexcept;

/// The transaction identifier of a whole frame.
inline std::uint16_t mbap_transaction(std::span<const std::uint8_t> frame) noexcept {
    return static_cast<std::uint16_t>(frame[0] << 8 | frame[1]);
}
/// The unit ID of a whole frame.
inline std::uint8_t mbap_unit(std::span<const std::uint8_t> frame) noexcept {
    return frame[kMbapPrefix];
}
/// The PDU of a whole frame: what follows the unit ID.
inline std::span<const std::uint8_t> mbap_pdu(std::span<const std::uint8_t> frame) noexcept {
    return frame.subspan(kMbapPrefix + 1);
}

/// Where a frame's PDU goes in `out`, so that it can be written in place and framed by
/// frame_mbap().
inline std::span<std::uint8_t> mbap_pdu_room(std::span<std::uint8_t> out) noexcept {
    return out.subspan(kMbapPrefix + 1);
}

/// Frames the `pdu_size` bytes of PDU already at mbap_pdu_room(out): writes the header before
/// them. Returns the frame's size; 0 when the PDU is empty or the frame would not fit.
std::size_t frame_mbap(std::uint16_t transaction,
                       std::uint8_t unit,
                       std::size_t pdu_size,
                       std::span<std::uint8_t> out) noexcept;

/// Writes a frame into `out`: transaction identifier, protocol identifier 0, the length, the
/// unit ID and `pdu`. Returns its size; 0 when `pdu` is empty or the frame would not fit.
std::size_t write_mbap(std::uint16_t transaction,
                       std::uint8_t unit,
                       std::span<const std::uint8_t> pdu,
                       std::span<std::uint8_t> out) noexcept;

}  // namespace plcemu::modbus
