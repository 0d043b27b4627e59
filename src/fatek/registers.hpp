#pragma once
// What 46 and 47 share: the start register's run and its count limit, 1-64 16-bit items or
// 1-32 32-bit ones (docs/profile-fbs.md, "FATEK protocol", limits).

#include <cstdint>

#include "head.hpp"
#include "names.hpp"

namespace plcemu::fatek {

/// Most registers a 46/47 request reads or writes: 64 words.
inline constexpr std::uint32_t kMaxWords = 64;

/// The width of a 46/47 value for a start name (a discrete, refused later, counts as a word).
constexpr Width register_width(const Head& h) noexcept {
    return h.error == Error::None && width_of(h.start.form) == Width::Dword ? Width::Dword
                                                                            : Width::Word;
}

/// Checks a 46/47 head after its format: the count (Value), then the start (Address); `run` is
/// the registers it names.
Error check_registers(const Head& h, const image::Layout& layout, Run& run) noexcept;

}  // namespace plcemu::fatek
