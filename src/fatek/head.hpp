#pragma once
// The head of a 43-47 request: a count `NN` (2 hex digits) and the start name.

#include <cstdint>
#include <span>

#include "names.hpp"

namespace plcemu::fatek {

/// A request's count and start name.
struct Head {
    Error error = Error::None;  ///< Format for a bad count or name, Address for an unknown prefix
    std::uint32_t count = 0;    ///< NN as written (00: 0)
    Name start;                 ///< the start name (when error is None)
    std::size_t size = 0;       ///< characters of NN and the name (when error is None)
};

/// Reads the count and start name at the front of `data`.
Head read_head(std::span<const std::uint8_t> data) noexcept;

}  // namespace plcemu::fatek
