#pragma once
// How many devices each area of a PLC has, which numbers inside an area do not exist, and which
// devices are retentive. A profile builds its Layout; the image only follows it.

#include <array>
#include <cstdint>
#include <string_view>
#include <vector>

#include "plcemu/image/area.hpp"

namespace plcemu::image {

/// Sizes of the areas of one PLC family, the numbers it lacks, and its retentive ranges.
struct Layout {
    /// A stable number of the family, recorded in state files: an image of one family is never
    /// taken for another's.
    std::uint32_t family = 0;
    /// The family's config name, for messages.
    std::string_view family_name;
    /// The config name of the family numbered `n` ("" for none), for a state file of another
    /// family; null: messages give the number only.
    std::string_view (*name_of_family)(std::uint32_t n) = nullptr;
    std::array<std::uint32_t, kAreaCount> size{};  ///< devices per area (0 = area absent)
    /// Numbers inside an area that no device has (D8000–D8999 between D7999 and D9000): kept in
    /// the image so that device numbers equal indices, refused everywhere else.
    std::vector<Range> holes;
    std::vector<Range> retentive;  ///< retentive ranges (kept across restart)

    /// Devices in area `a`.
    std::uint32_t size_of(Area a) const { return size[static_cast<std::size_t>(a)]; }
    /// Gives area `a` `n` devices (0: the family has no such area).
    void set_size(Area a, std::uint32_t n) { size[static_cast<std::size_t>(a)] = n; }
    /// True when every device of the range exists.
    bool contains(const Range& r) const {
        if (r.count > size_of(r.area) || r.start > size_of(r.area) - r.count) return false;
        for (const auto& h : holes) {
            if (h.overlaps(r)) return false;
        }
        return true;
    }
};

}  // namespace plcemu::image
