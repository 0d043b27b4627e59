#pragma once
// Function codes as a table of handlers, one per code or family, each in its own file under
// src/modbus/functions/. A handler sees the request's PDU and the unit it is for, never the
// transport: the dispatcher routes unit IDs, frames replies and turns refusals into exceptions.

#include <array>
#include <cstddef>
#include <cstdint>
#include <span>

#include "plcemu/modbus/dispatcher.hpp"
#include "plcemu/modbus/unit.hpp"

namespace plcemu::modbus {

/// A request as a handler sees it.
struct FunctionRequest {
    std::span<const std::uint8_t> pdu;  ///< function code first
    Unit& unit;                         ///< the unit addressed
    std::uint8_t slave_id;              ///< the ID it answers as (the station for the PLC)
    bool broadcast;  ///< RTU unit 0: writes are applied; the dispatcher sends no reply at all
    const Identity& identity;  ///< FC 11h and 2Bh/0Eh
};

/// What a handler decided.
struct FunctionReply {
    Status status = Status::Ok;  ///< not Ok: the dispatcher answers with this exception
    std::size_t size = 0;        ///< bytes of the reply PDU; 0 with Ok: nothing is sent

    /// A refusal.
    static FunctionReply refuse(Status s) { return {s, 0}; }
    /// No answer (a broadcast).
    static FunctionReply none() { return {}; }
    /// A reply PDU of `n` bytes.
    static FunctionReply pdu(std::size_t n) { return {Status::Ok, n}; }
};

/// The memory of a whole request: the windows of consecutive parts, in wire order. A request
/// within one map row (nearly all) has one part.
struct Span {
    static constexpr std::size_t kMaxParts = 8;    ///< more rows than this in one request: 02
    Status status = Status::IllegalDataAddress;    ///< Ok, or the first part's refusal
    std::array<Window, kMaxParts> parts{};         ///< the windows
    std::array<std::uint16_t, kMaxParts> first{};  ///< element index each part starts at
    std::size_t n = 0;                             ///< parts used

    /// The part holding element `i`, and `i` within it.
    const Window& at(std::size_t& i) const {
        std::size_t k = n - 1;
        while (k > 0 && i < first[k]) --k;
        i -= first[k];
        return parts[k];
    }
    /// Coil or discrete input `i`.
    bool bit(std::size_t i) const {
        const Window& w = at(i);
        return w.bits[i] != 0;
    }
    /// Writes coil `i`.
    void set_bit(std::size_t i, bool v) const {
        const Window& w = at(i);
        w.bits[i] = v ? 1 : 0;
    }
    /// Register `i`.
    std::uint16_t word(std::size_t i) const {
        const Window& w = at(i);
        return w.word(i);
    }
    /// Writes register `i`.
    void set_word(std::size_t i, std::uint16_t v) const {
        const Window& w = at(i);
        w.set_word(i, v);
    }
};

/// Resolves `qty` elements from `addr` part by part, each part as far as one device range goes;
/// every part must resolve (and, for a write, be writable) before anything is touched.
Span resolve_span(
    Unit& unit, Table table, std::uint16_t addr, std::uint16_t qty, bool write) noexcept;

/// Function code → handler; nullptr: exception 01.
using FunctionTable = std::array<FunctionHandler, 128>;

/// The codes every profile serves: 01–06, 08, 0Fh, 10h, 11h, 16h, 17h, 2Bh.
FunctionTable standard_functions();

namespace functions {
/// FC 01: read coils.
FunctionReply read_coils(const FunctionRequest& r, PduBuffer out) noexcept;
/// FC 02: read discrete inputs.
FunctionReply read_discrete_inputs(const FunctionRequest& r, PduBuffer out) noexcept;
/// FC 03: read holding registers.
FunctionReply read_holding_registers(const FunctionRequest& r, PduBuffer out) noexcept;
/// FC 04: read input registers.
FunctionReply read_input_registers(const FunctionRequest& r, PduBuffer out) noexcept;
/// FC 05: write single coil.
FunctionReply write_single_coil(const FunctionRequest& r, PduBuffer out) noexcept;
/// FC 06: write single register.
FunctionReply write_single_register(const FunctionRequest& r, PduBuffer out) noexcept;
/// FC 0Fh: write multiple coils.
FunctionReply write_multiple_coils(const FunctionRequest& r, PduBuffer out) noexcept;
/// FC 10h: write multiple registers.
FunctionReply write_multiple_registers(const FunctionRequest& r, PduBuffer out) noexcept;
/// FC 16h: mask write register.
FunctionReply mask_write_register(const FunctionRequest& r, PduBuffer out) noexcept;
/// FC 08: diagnostics, subfunction 00 (return query data).
FunctionReply diagnostics(const FunctionRequest& r, PduBuffer out) noexcept;
/// FC 11h: report slave ID.
FunctionReply report_slave_id(const FunctionRequest& r, PduBuffer out) noexcept;
/// FC 17h: read/write multiple registers, the write first.
FunctionReply read_write_registers(const FunctionRequest& r, PduBuffer out) noexcept;
/// FC 2Bh/0Eh: read device identification.
FunctionReply device_identification(const FunctionRequest& r, PduBuffer out) noexcept;
}  // namespace functions

}  // namespace plcemu::modbus
