#pragma once
// Device areas of a PLC and the ranges that address them.

#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace plcemu::image {

/// A device area. Bit areas hold one byte per bit (0 or 1); word areas hold uint16_t.
enum class Area : std::uint8_t {
    X,   ///< discrete inputs (bits)
    Y,   ///< discrete outputs (bits)
    M,   ///< internal relays (bits)
    S,   ///< step relays (bits)
    T,   ///< timer status bits
    C,   ///< counter status bits
    R,   ///< registers R0.. (words)
    D,   ///< data registers D0.. (words)
    TV,  ///< timer current values (words)
    CV,  ///< counter current values (words; 32-bit counters take two, low word first)
};

/// Number of areas, for tables indexed by Area.
inline constexpr std::size_t kAreaCount = 10;

/// True for the areas that hold bits.
constexpr bool is_bit_area(Area a) {
    return a == Area::X || a == Area::Y || a == Area::M || a == Area::S || a == Area::T ||
           a == Area::C;
}

/// The area's name in this code ("X", "R", "TV", "CV"); a family's own spelling is its
/// Naming's (plcemu/image/naming.hpp).
std::string_view area_name(Area a);

/// A contiguous run of devices in one area, e.g. D100–D199.
struct Range {
    Area area = Area::R;      ///< the area
    std::uint32_t start = 0;  ///< first device index
    std::uint32_t count = 0;  ///< number of devices (bits or words)

    /// One past the last index.
    std::uint32_t end() const { return start + count; }
    /// True when the two ranges share at least one device.
    bool overlaps(const Range& o) const {
        return area == o.area && start < o.end() && o.start < end();
    }
    /// True when `o` lies wholly inside this range.
    bool contains(const Range& o) const {
        return area == o.area && o.start >= start && o.end() <= end();
    }
    bool operator==(const Range&) const = default;
};

/// True when the two lists cover the same devices, whatever their order or split: [R0-R9, D0]
/// and [D0, R5-R9, R0-R4] are one set.
bool same_devices(const std::vector<Range>& a, const std::vector<Range>& b);

/// One device operand as written in a config: a bit (M0), a word (R100), or 16 bits read as a
/// word (WM800).
struct Device {
    Area area = Area::R;        ///< area of the device (for WMn: M)
    std::uint32_t index = 0;    ///< index within the area
    bool word_of_bits = false;  ///< "W" prefix: 16 consecutive bits taken as one word

    bool operator==(const Device&) const = default;
};

}  // namespace plcemu::image
