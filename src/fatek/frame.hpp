#pragma once
// The FATEK frame (FBs manual, Appendix 2 FATEK Communication Protocol): STX, station (2 hex),
// command (2 hex), 0-500 data characters, checksum (2 hex), ETX. The sizes every part of the
// protocol shares.

#include <cstddef>
#include <cstdint>

namespace plcemu::fatek {

inline constexpr std::uint8_t kStx = 0x02;  ///< start of a frame
inline constexpr std::uint8_t kEtx = 0x03;  ///< end of a frame
/// Most data characters a frame carries.
inline constexpr std::size_t kMaxData = 500;
/// STX, station, command, checksum, ETX: the bytes of a frame around its data.
inline constexpr std::size_t kFrameOverhead = 8;
/// Largest frame in either direction: 508 bytes.
inline constexpr std::size_t kMaxFrame = kFrameOverhead + kMaxData;
/// Where the data starts (after STX, station and command).
inline constexpr std::size_t kDataAt = 5;

}  // namespace plcemu::fatek
