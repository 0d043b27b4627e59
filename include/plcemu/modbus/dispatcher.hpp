#pragma once
// Request dispatch: function code, validation, address resolution, reply PDU. The one place
// where refusals become Modbus exceptions.

#include <array>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <span>
#include <string>

#include "plcemu/modbus/limits.hpp"
#include "plcemu/modbus/unit.hpp"

namespace plcemu::modbus {

/// Identification strings for FC 11h and 2Bh/0Eh.
struct Identity {
    std::string vendor;    ///< VendorName: the profile's vendor
    std::string product;   ///< ProductCode: the model
    std::string revision;  ///< MajorMinorRevision: the emulator's version
};

/// Counters, for logs and tests.
struct DispatchStats {
    std::uint64_t requests = 0;    ///< requests served, answered or not
    std::uint64_t exceptions = 0;  ///< exception replies sent
};

/// Where a function handler builds its reply PDU.
using PduBuffer = std::span<std::uint8_t, kMaxPdu>;
struct FunctionRequest;
struct FunctionReply;
/// One function code's handler (plcemu/modbus/function_handler.hpp).
using FunctionHandler = FunctionReply (*)(const FunctionRequest&, PduBuffer out) noexcept;

/// A request as a listener's unit table routed it: a PDU for one unit.
struct Request {
    std::span<const std::uint8_t> pdu;  ///< function code first; at least one byte
    Unit& unit;                         ///< the unit addressed: the PLC, or its simulator unit
    std::uint8_t slave_id;              ///< the ID it answers as (FC 11h): the station, or the unit
    bool broadcast = false;             ///< RTU unit 0: served, never answered
};

/// Writes the exception PDU answering function `fc` with code `s` into `out`; returns its size.
std::size_t exception_pdu(std::uint8_t fc, Status s, PduBuffer out) noexcept;

/// One PLC's side of the protocol: its function codes and identity. A function from a request
/// to a reply PDU, an exception PDU or nothing; it never sees a header, a CRC or a socket (the
/// framing belongs to the transport, the unit IDs to the listener's unit table).
class Dispatcher final {
public:
    explicit Dispatcher(Identity identity);
    ~Dispatcher();
    Dispatcher(const Dispatcher&) = delete;
    Dispatcher& operator=(const Dispatcher&) = delete;

    /// Serves function code `fc` (below 80h) with `handler`, or refuses it with exception 01
    /// when `handler` is null: a profile adds or refuses codes (see
    /// plcemu/modbus/function_handler.hpp).
    void set_function(std::uint8_t fc, FunctionHandler handler);

    /// Serves one request; the reply PDU, or the exception PDU that refuses it, goes to `out`.
    /// Returns its size, 0 when nothing is to be sent (a broadcast).
    std::size_t answer(const Request& request, PduBuffer out) noexcept;

    /// Counters since start.
    const DispatchStats& stats() const { return stats_; }

private:
    Identity identity_;
    std::array<FunctionHandler, 128> functions_;
    DispatchStats stats_;
};

}  // namespace plcemu::modbus
