#pragma once
// The FATEK frame checksum (FBs manual, Appendix 2 FATEK Communication Protocol): the low byte of
// the plain sum of every byte from STX to the last data byte. The manual calls it "LRC", but it
// is no two's complement.

#include <cstdint>
#include <span>

namespace plcemu::fatek {

/// The checksum of `bytes` (STX, station, command and data).
std::uint8_t checksum(std::span<const std::uint8_t> bytes) noexcept;

}  // namespace plcemu::fatek
