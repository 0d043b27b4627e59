#pragma once
// Request dispatch: unit ID, function code, validation, address resolution, reply. The one
// place where refusals become Modbus exceptions.

#include <array>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <span>
#include <string>

#include "plcemu/modbus/responder.hpp"
#include "plcemu/modbus/unit.hpp"

namespace plcemu::modbus {

/// Which framing a request arrived in.
enum class Transport : std::uint8_t { Tcp, Rtu };

/// What the dispatcher does with TCP unit IDs other than the station, 255 and the simulator.
enum class UnknownUnitPolicy : std::uint8_t { Exception, Silent };

/// Identification strings for FC 11h and 2Bh/0Eh.
struct Identity {
    std::string vendor;    ///< VendorName: the profile's vendor
    std::string product;   ///< ProductCode: the model
    std::string revision;  ///< MajorMinorRevision: the emulator's version
};

/// Counters, for logs and tests.
struct DispatchStats {
    std::uint64_t requests = 0;    ///< requests for a unit served here, answered or not
    std::uint64_t exceptions = 0;  ///< exception replies sent
    std::uint64_t ignored = 0;     ///< requests dropped without an answer
};

/// The largest PDU.
inline constexpr std::size_t kMaxPdu = 253;
/// Where a function handler builds its reply PDU.
using PduBuffer = std::span<std::uint8_t, kMaxPdu>;
struct FunctionRequest;
struct FunctionReply;
/// One function code's handler (plcemu/modbus/function_handler.hpp).
using FunctionHandler = FunctionReply (*)(const FunctionRequest&, PduBuffer out) noexcept;

/// The exception reply to `adu` (a TCP ADU or an RTU frame) with code `s`, framed like the
/// request, into `out`. Returns its length.
std::size_t exception_reply(Transport t,
                            std::span<const std::uint8_t> adu,
                            Status s,
                            ReplyBuffer out) noexcept;

/// One PLC's side of the protocol: its station (and the simulator unit beside it), the function
/// codes, the reply.
class Dispatcher final : public Responder {
public:
    /// `plc` and `station` must outlive the dispatcher; `station` is read on every request
    /// (it changes when a master writes 55xxh to R4055).
    Dispatcher(Unit& plc, const std::uint8_t& station, Identity identity);
    ~Dispatcher() override;
    Dispatcher(const Dispatcher&) = delete;
    Dispatcher& operator=(const Dispatcher&) = delete;

    /// Serves a second unit (the simulator-control unit) under `unit_id` (0 = none).
    void set_simulator(Unit* sim, std::uint8_t unit_id);
    /// Serves function code `fc` (below 80h) with `handler`, or refuses it with exception 01
    /// when `handler` is null: a profile adds or refuses codes (see
    /// plcemu/modbus/function_handler.hpp).
    void set_function(std::uint8_t fc, FunctionHandler handler);
    /// Sets the TCP policy for unknown unit IDs.
    void set_unknown_unit_policy(UnknownUnitPolicy p) { unknown_unit_ = p; }
    /// The station now (R4055 may have changed it since the start).
    std::uint8_t station() const { return station_; }
    /// The simulator-control unit's ID, 0 when there is none.
    std::uint8_t simulator_unit() const { return sim_ != nullptr ? sim_unit_ : 0; }

    /// Serves one complete TCP ADU (MBAP header + PDU); the reply ADU goes to `out`. Returns its
    /// length, 0 when nothing is to be sent.
    std::size_t serve_tcp(std::span<const std::uint8_t> adu, ReplyBuffer out) noexcept override;
    /// Serves one complete RTU frame (address, PDU, CRC already checked); the reply frame with
    /// its CRC goes to `out`. Returns its length, 0 when nothing is to be sent (broadcasts).
    std::size_t serve_rtu(std::span<const std::uint8_t> frame, ReplyBuffer out) noexcept override;

    /// Counters since start.
    const DispatchStats& stats() const { return stats_; }

private:
    std::size_t serve(Transport t, std::span<const std::uint8_t> adu, ReplyBuffer out) noexcept;

    Unit& plc_;
    const std::uint8_t& station_;
    Identity identity_;
    Unit* sim_ = nullptr;
    std::uint8_t sim_unit_ = 0;
    UnknownUnitPolicy unknown_unit_ = UnknownUnitPolicy::Exception;
    std::array<FunctionHandler, 128> functions_;
    DispatchStats stats_;
};

}  // namespace plcemu::modbus
