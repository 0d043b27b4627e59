#pragma once
// Request dispatch: unit ID, function code, validation, address resolution, reply. The one
// place where refusals become Modbus exceptions.

#include <array>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <span>
#include <string>

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

/// Largest reply ADU: MBAP header (7) + PDU (253); an RTU reply (1 + 253 + 2) is shorter.
inline constexpr std::size_t kMaxReplyAdu = 260;
/// Where a reply is built; the transport writes it (the dispatcher never touches a socket).
using ReplyBuffer = std::span<std::uint8_t, kMaxReplyAdu>;

/// Turns complete request frames into reply frames in a buffer the transport owns.
class Dispatcher {
public:
    /// `plc` and `station` must outlive the dispatcher; `station` is read on every request
    /// (it changes when a master writes 55xxh to R4055).
    Dispatcher(Unit& plc, const std::uint8_t& station, Identity identity);
    ~Dispatcher();
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

    /// Serves one complete TCP ADU (MBAP header + PDU); the reply ADU goes to `out`. Returns its
    /// length, 0 when nothing is to be sent.
    std::size_t serve_tcp(std::span<const std::uint8_t> adu, ReplyBuffer out) noexcept;
    /// Serves one complete RTU frame (address, PDU, CRC already checked); the reply frame with
    /// its CRC goes to `out`. Returns its length, 0 when nothing is to be sent (broadcasts).
    std::size_t serve_rtu(std::span<const std::uint8_t> frame, ReplyBuffer out) noexcept;

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
