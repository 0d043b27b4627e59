#pragma once
// The devices a FATEK request names, for the communication faults' scope
// (docs/communication-faults.md): 42's discrete, 43-47's run from NN and the start name, 48's
// and 49's items. Names that do not resolve reach nothing (the handler refuses them anyway).

#include <cstdint>
#include <optional>
#include <span>

#include "plcemu/image/area.hpp"
#include "plcemu/image/layout.hpp"

namespace plcemu::fatek {

/// The first range of devices that command `code` with `data` reaches in `layout` and that
/// overlaps `scope`; nothing when none does (or the command names no devices).
std::optional<image::Range> reach_within(std::uint8_t code,
                                         std::span<const std::uint8_t> data,
                                         const image::Layout& layout,
                                         const image::Range& scope) noexcept;

}  // namespace plcemu::fatek
