#include "unit_router.hpp"

#include <spdlog/spdlog.h>

#include <algorithm>

namespace plcemu::modbus {

namespace {

// MBAP header (7 bytes, the unit last) and function code; RTU address and function code.
constexpr std::size_t kTcpUnit = 6;
constexpr std::size_t kTcpMin = 8;
constexpr std::size_t kRtuMin = 4;

}  // namespace

void UnitRouter::add(Dispatcher& d) { members_.push_back(&d); }

void UnitRouter::clear() { members_.clear(); }

Dispatcher* UnitRouter::find(std::uint8_t unit) noexcept {
    // A plain search: stations change at run time (R4055), a listener holds at most a few hundred
    // PLCs, and two bytes per PLC are compared.
    for (Dispatcher* d : members_) {
        if (d->station() == unit || d->simulator_unit() == unit) return d;
    }
    return nullptr;
}

std::size_t UnitRouter::serve_tcp(std::span<const std::uint8_t> adu, ReplyBuffer out) noexcept {
    if (members_.size() == 1) return members_.front()->serve_tcp(adu, out);
    if (members_.empty() || adu.size() < kTcpMin) return 0;
    const std::uint8_t unit = adu[kTcpUnit];
    if (unit != 0 && unit != 0xFF) {
        if (Dispatcher* d = find(unit)) return d->serve_tcp(adu, out);
    }
    ++stats_.unrouted;
    spdlog::debug("modbus: unit {} is no PLC's on this listener{}", unit,
                  unknown_unit_ == UnknownUnitPolicy::Exception ? ": exception 0Bh" : "");
    if (unknown_unit_ == UnknownUnitPolicy::Silent) return 0;
    return exception_reply(Transport::Tcp, adu, Status::GatewayTargetFailed, out);
}

std::size_t UnitRouter::serve_rtu(std::span<const std::uint8_t> frame, ReplyBuffer out) noexcept {
    if (members_.size() == 1) return members_.front()->serve_rtu(frame, out);
    if (members_.empty() || frame.size() < kRtuMin) return 0;
    const std::uint8_t unit = frame[0];
    if (unit == 0) {
        ++stats_.broadcasts;
        for (Dispatcher* d : members_) d->serve_rtu(frame, out);  // a broadcast has no answer
        return 0;
    }
    if (Dispatcher* d = find(unit)) return d->serve_rtu(frame, out);
    ++stats_.unrouted;
    return 0;
}

}  // namespace plcemu::modbus
