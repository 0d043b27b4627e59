#pragma once
// How many devices each area of a profile has, and which of them are retentive.

#include <array>
#include <cstdint>
#include <string_view>
#include <vector>

#include "plcemu/image/area.hpp"

namespace plcemu::image {

/// The PLC families the emulator knows.
enum class Profile : std::uint8_t { Fbs, Fb, Vb };

/// Parses "fbs" / "fb" / "vb".
bool parse_profile(std::string_view text, Profile& out);
/// The config spelling of a profile.
std::string_view profile_name(Profile p);

/// Sizes of the areas of one profile, plus its default retentive ranges.
struct Layout {
    std::array<std::uint32_t, kAreaCount> size{};  ///< devices per area (0 = area absent)
    std::vector<Range> retentive;                  ///< retentive ranges (kept across restart)

    /// Devices in area `a`.
    std::uint32_t size_of(Area a) const { return size[static_cast<std::size_t>(a)]; }
    /// True when the range lies inside its area.
    bool contains(const Range& r) const {
        return r.count <= size_of(r.area) && r.start <= size_of(r.area) - r.count;
    }
};

/// The FBs layout of SPEC §1 with its default retentive ranges.
Layout fbs_layout();

/// The layout of a profile (only `fbs` is specified so far; others throw std::invalid_argument).
Layout layout_for(Profile p);

}  // namespace plcemu::image
