#pragma once
// One listener, several PLCs: a request goes to the PLC whose station (live: R4055 may change
// it) or simulator unit its unit ID names (docs/configuration.md, "Sharing a listener").

#include <cstdint>
#include <vector>

#include "plcemu/modbus/dispatcher.hpp"
#include "plcemu/modbus/responder.hpp"

namespace plcemu::modbus {

/// Counters of what no PLC took, for logs and tests.
struct RouterStats {
    std::uint64_t unrouted = 0;    ///< requests for a unit no PLC has
    std::uint64_t broadcasts = 0;  ///< RTU broadcasts handed to every PLC
};

/// Routes a shared listener's requests by unit ID. With one PLC it hands every request to that
/// PLC's dispatcher unchanged, so a listener of its own behaves exactly as one without a router.
/// With several:
/// - RTU: a frame for a station or simulator unit goes to its PLC; a broadcast (unit 0) to every
///   PLC, in order (none answers it); a frame for a unit nobody has is ignored, as on a real
///   RS-485 line.
/// - TCP: a unit ID goes to its PLC; units 0 and 255, which name "the device itself" (Modbus TCP
///   implementation guide §4.4.1.2), name no single PLC behind a shared listener, so they and
///   every unit nobody has get the listener's unknown-unit policy (exception 0Bh, or silence).
/// Unit IDs are unique on a listener: the config loader refuses duplicates, and the daemon
/// refuses a station change (R4055) or a reload that would make one. Should two PLCs answer one
/// unit anyway, the first added answers.
class UnitRouter final : public Responder {
public:
    /// Routes to `d` too (after those added before it). `d` must outlive its membership.
    void add(Dispatcher& d);
    /// Routes to nobody.
    void clear();
    /// PLCs routed to.
    std::size_t size() const { return members_.size(); }
    /// The TCP policy for units no PLC has, when the listener is shared.
    void set_unknown_unit_policy(UnknownUnitPolicy p) { unknown_unit_ = p; }

    std::size_t serve_tcp(std::span<const std::uint8_t> adu, ReplyBuffer out) noexcept override;
    std::size_t serve_rtu(std::span<const std::uint8_t> frame, ReplyBuffer out) noexcept override;

    /// Counters since start.
    const RouterStats& stats() const { return stats_; }

private:
    /// The PLC that has `unit` as its station or simulator unit, or null.
    Dispatcher* find(std::uint8_t unit) noexcept;

    std::vector<Dispatcher*> members_;
    UnknownUnitPolicy unknown_unit_ = UnknownUnitPolicy::Exception;
    RouterStats stats_;
};

}  // namespace plcemu::modbus
