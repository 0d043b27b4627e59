#pragma once
// Modbus TCP framing: where the next MBAP frame of a byte stream ends. A pure function, so the
// TCP server and the fuzz harness split a stream the same way.

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

}  // namespace plcemu::modbus
