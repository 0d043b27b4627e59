#include "rtu_reply.hpp"

#include <algorithm>

#include "crc.hpp"

namespace plcemu::modbus {

namespace {

// Address, function code, CRC: the shortest frame that carries a PDU.
constexpr std::size_t kMinFrame = 4;

}  // namespace

RtuReply rtu_reply(const RtuFrame& frame, std::uint8_t station) noexcept {
    RtuReply r;
    const auto b = frame.bytes;
    // The framer checked the CRC and the pauses; the address is the master's business: on a
    // line where only the master speaks first, a frame from another station answers nothing.
    if (frame.verdict != RtuVerdict::Ok || b.size() < kMinFrame || b[0] != station) return r;
    r.outcome = MasterOutcome::Reply;
    r.pdu = b.subspan(1, b.size() - 3);
    return r;
}

std::size_t rtu_request(std::uint8_t station,
                        std::span<const std::uint8_t> pdu,
                        std::span<std::uint8_t> out) noexcept {
    const std::size_t n = pdu.size() + 3;
    if (pdu.empty() || n > out.size() || n > RtuFramer::kMaxFrame) return 0;
    out[0] = station;
    std::copy(pdu.begin(), pdu.end(), out.begin() + 1);
    const std::uint16_t crc = crc16(out.data(), n - 2);
    out[n - 2] = static_cast<std::uint8_t>(crc & 0xFF);
    out[n - 1] = static_cast<std::uint8_t>(crc >> 8);
    return n;
}

}  // namespace plcemu::modbus
