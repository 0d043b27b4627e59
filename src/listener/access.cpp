#include "plcemu/listener/access.hpp"

#include <algorithm>

namespace plcemu::listener {

std::optional<image::Range> write_refused_by(const std::vector<image::Range>* protected_ranges,
                                             const engine::Holds& holds,
                                             const image::Range& devices) noexcept {
    if (protected_ranges == nullptr) return std::nullopt;
    for (const image::Range& p : *protected_ranges) {
        if (!p.overlaps(devices)) continue;
        // An input is written only while it is disabled (FATEK command 42); every other
        // protected device, a disabled one too, refuses a master's write.
        if (devices.area != image::Area::X) return p;
        const std::uint32_t to = std::min(p.end(), devices.end());
        for (std::uint32_t i = std::max(p.start, devices.start); i < to; ++i) {
            if (!holds.held(devices.area, i)) return p;
        }
    }
    return std::nullopt;
}

}  // namespace plcemu::listener
