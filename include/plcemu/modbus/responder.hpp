#pragma once
// What a transport hands its complete request frames to: one PLC's dispatcher, or the router of
// a listener several PLCs share (src/modbus/unit_router.hpp).

#include <cstddef>
#include <cstdint>
#include <span>

namespace plcemu::modbus {

/// Largest reply ADU: MBAP header (7) + PDU (253); an RTU reply (1 + 253 + 2) is shorter.
inline constexpr std::size_t kMaxReplyAdu = 260;
/// Where a reply is built; the transport writes it (the dispatcher never touches a socket).
using ReplyBuffer = std::span<std::uint8_t, kMaxReplyAdu>;

/// Turns complete request frames into reply frames in a buffer the transport owns.
class Responder {
public:
    virtual ~Responder() = default;
    Responder() = default;
    Responder(const Responder&) = delete;
    Responder& operator=(const Responder&) = delete;

    /// Serves one complete TCP ADU (MBAP header + PDU); the reply ADU goes to `out`. Returns its
    /// length, 0 when nothing is to be sent.
    virtual std::size_t serve_tcp(std::span<const std::uint8_t> adu, ReplyBuffer out) noexcept = 0;
    /// Serves one complete RTU frame (address, PDU, CRC already checked); the reply frame with
    /// its CRC goes to `out`. Returns its length, 0 when nothing is to be sent (broadcasts).
    virtual std::size_t serve_rtu(std::span<const std::uint8_t> frame,
                                  ReplyBuffer out) noexcept = 0;
};

}  // namespace plcemu::modbus
