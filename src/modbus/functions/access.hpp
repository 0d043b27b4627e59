#pragma once
// What the data-access handlers (FC 01-06, 0Fh, 10h, 16h, one file each) share: a request's
// parsed fields, and the order in which the PLC refuses one.
//
// The replies are built by the handlers rather than by libmodbus' modbus_reply(): libmodbus 3.1
// can only write a reply to a descriptor, and reading it back from a socket pair cost a third
// of the throughput at 16 connections (docs/performance.md, "Who frames the reply"). libmodbus
// is the reference they are held to instead (docs/testing.md).

#include <optional>

#include "plcemu/modbus/function_handler.hpp"

namespace plcemu::modbus::functions {

/// What a request asks for, once its format has been checked.
struct Access {
    Status status = Status::Ok;  ///< IllegalDataValue when malformed
    Table table = Table::HoldingRegisters;
    std::uint16_t addr = 0;
    std::uint16_t qty = 0;
    bool write = false;
};

/// `v` within [lo, hi].
inline bool in(std::uint16_t v, std::uint16_t lo, std::uint16_t hi) { return v >= lo && v <= hi; }

/// `a` marked malformed (exception 03).
inline Access malformed(Access a) {
    a.status = Status::IllegalDataValue;
    return a;
}

/// A request of address and quantity (or value): FC 01-06. Its size is checked (5 bytes) and
/// its fields read; malformed with nothing read otherwise.
Access address_and_quantity(const FunctionRequest& r, Table table);

/// Resolves the request's memory into `w` and says why it is refused, in the order the PLC
/// answers: a table the unit does not serve (01) before a malformed request (03) before an
/// address it does not have or may not write (02). A broadcast read is ignored (no answer).
/// Nothing when the handler may go on.
std::optional<FunctionReply> refusal(const FunctionRequest& r, const Access& a, Span& w) noexcept;

/// A write's reply: the request's function code and its next `n` bytes (address and value or
/// quantity, and masks for FC 16h), after the unit heard of the write.
FunctionReply echo(const FunctionRequest& r, const Access& a, std::size_t n, PduBuffer out);

}  // namespace plcemu::modbus::functions
