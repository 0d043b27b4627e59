#pragma once
// Where a FATEK frame ends in a byte stream (docs/profile-fbs.md, "FATEK protocol", framing):
// bytes before an STX are skipped, an STX always starts a new frame, the first ETX ends it, and
// 508 bytes without one are dropped. A FATEK stream never loses its frame boundaries, so
// nothing is "bad": what is to be skipped is cut off as a frame that answer() leaves unanswered.

#include <cstdint>
#include <span>

#include "plcemu/listener/protocol.hpp"

namespace plcemu::fatek {

/// The next piece of `buffered`: Incomplete, or a Frame of n bytes (a whole frame, or bytes to
/// skip). Never Bad.
listener::Split split_stream(std::span<const std::uint8_t> buffered) noexcept;

}  // namespace plcemu::fatek
