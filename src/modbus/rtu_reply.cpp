#include "rtu_reply.hpp"

#include "rtu_frame.hpp"

namespace plcemu::modbus {

RtuReply rtu_reply(const RtuFrame& frame, std::uint8_t station) noexcept {
    RtuReply r;
    const auto b = frame.bytes;
    // The framer checked the CRC and the pauses; the address is the master's business: on a
    // line where only the master speaks first, a frame from another station answers nothing.
    if (frame.verdict != RtuVerdict::Ok || b.size() < kMinRtuFrame || rtu_address(b) != station)
        return r;
    r.outcome = MasterOutcome::Reply;
    r.pdu = rtu_pdu(b);
    return r;
}

}  // namespace plcemu::modbus
