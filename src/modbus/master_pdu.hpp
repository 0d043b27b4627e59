#pragma once
// The master side of a Modbus exchange: a request PDU built from a function code, an address, a
// quantity and the values to write, and a reply PDU checked against the request it answers.
// Pure functions, shared by the TCP and RTU masters and the fuzz harnesses.

#include <cstddef>
#include <cstdint>
#include <span>

#include "plcemu/modbus/limits.hpp"

namespace plcemu::modbus {

/// Largest request PDU a master builds: FC16 with 123 registers.
inline constexpr std::size_t kMaxRequestPdu = kMaxPdu;

/// Builds the request PDU of `function` (1–4 reads, 5, 6, 15, 16 writes) into `out`: FC05 writes
/// FF00h for a non-zero value, FC15/16 take `quantity` values. Returns its size; 0 for another
/// function code, a quantity outside 1–123 (registers) or 1–1968 (bits), too few values or too
/// small a buffer.
std::size_t encode_request(std::uint8_t function,
                           std::uint16_t address,
                           std::uint16_t quantity,
                           std::span<const std::uint16_t> values,
                           std::span<std::uint8_t> out) noexcept;

/// True for the write functions a master sends (5, 6, 15, 16).
bool is_write(std::uint8_t function) noexcept;

/// What a reply says about its request.
enum class ReplyVerdict : std::uint8_t {
    Ok,         ///< answers the request (a read's values were taken)
    Exception,  ///< an exception reply to the request's function code
    Malformed,  ///< wrong function code, byte count, length or echo
};

/// A checked reply.
struct ReplyCheck {
    ReplyVerdict verdict = ReplyVerdict::Malformed;  ///< what it is
    std::uint8_t exception = 0;                      ///< the code of an exception reply
};

/// Checks `reply` against `request` (both PDUs, function code first): a read's byte count and
/// length, a write's echoed address and quantity (FC05/06: value). A read's values go to
/// `values` (bits as 0/1), which must hold the request's quantity.
ReplyCheck check_reply(std::span<const std::uint8_t> request,
                       std::span<const std::uint8_t> reply,
                       std::span<std::uint16_t> values) noexcept;

}  // namespace plcemu::modbus
