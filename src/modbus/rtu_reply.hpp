#pragma once
// What a Modbus RTU master makes of a frame the RTU framer ended while it waited for a reply:
// the reply PDU of the station it asked, or garbage (a bad CRC, a pause inside the frame, a
// fragment, another station). Pure, shared by the RTU master and its fuzz harness.

#include <cstdint>
#include <span>

#include "master_transport.hpp"
#include "rtu_framer.hpp"

namespace plcemu::modbus {

/// A frame judged as the reply to a request sent to one station.
struct RtuReply {
    MasterOutcome outcome = MasterOutcome::Garbled;  ///< Reply or Garbled
    std::span<const std::uint8_t> pdu;               ///< the reply PDU (Reply only)
};

/// Judges `frame` as the reply of `station` (1–247): Reply with the PDU between the address and
/// the CRC when the frame is whole, its CRC good and its address the station's; else Garbled.
RtuReply rtu_reply(const RtuFrame& frame, std::uint8_t station) noexcept;

}  // namespace plcemu::modbus
