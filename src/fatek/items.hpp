#pragma once
// The values of resolved items (names.hpp) in the image, and whether a master may write them
// (docs/profile-fbs.md, "FATEK protocol", errors): a register no master may write is refused, a
// discrete no master may write (an input) only while it is disabled.

#include <cstdint>
#include <vector>

#include "names.hpp"
#include "plcemu/engine/holds.hpp"
#include "plcemu/image/image.hpp"

namespace plcemu::fatek {

/// Item `k` of `run`: 0/1, a word or a 32-bit value.
std::uint32_t read_item(const image::Image& image, const Run& run, std::uint32_t k) noexcept;
/// Writes item `k` of `run`.
void write_item(image::Image& image, const Run& run, std::uint32_t k, std::uint32_t v) noexcept;
/// True when a master may write every item of `run`.
bool writable(const Run& run,
              const std::vector<image::Range>* protected_ranges,
              const engine::Holds& holds) noexcept;

}  // namespace plcemu::fatek
