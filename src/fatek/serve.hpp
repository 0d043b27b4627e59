#pragma once
// A FATEK request to the PLCs behind a listener (docs/profile-fbs.md, "FATEK protocol",
// stations): the PLC whose station it names answers with its own station; station 0 is served by
// every PLC and answered by none; a frame for nobody here, for a simulator unit or a dropped
// frame gets no reply.

#include <cstdint>
#include <span>

#include "plcemu/listener/unit_table.hpp"

namespace plcemu::fatek {

/// Answers the whole frame `frame` into `out` (at least kMaxFrame bytes); returns the reply's
/// size, 0 when nothing is to be sent. On a read-only listener (`units.read_only()`, read for
/// every request) every command that changes the PLC is refused with error 3.
std::size_t serve(listener::UnitTable& units,
                  std::span<const std::uint8_t> frame,
                  std::span<std::uint8_t> out) noexcept;

}  // namespace plcemu::fatek
