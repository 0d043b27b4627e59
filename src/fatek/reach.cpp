#include "reach.hpp"

#include "head.hpp"
#include "mixed.hpp"
#include "names.hpp"

namespace plcemu::fatek {

namespace {

// The devices `items` items from `name` cover, or nothing when they do not resolve.
std::optional<image::Range> devices(const Name& name,
                                    std::uint32_t items,
                                    const image::Layout& layout) noexcept {
    Run run;
    if (resolve(name, items, layout, run) != Error::None) return std::nullopt;
    return image::Range{run.area, run.start, run.items * run.step};
}

std::optional<image::Range> within(std::optional<image::Range> r, const image::Range& scope) {
    if (r && r->overlaps(scope)) return r;
    return std::nullopt;
}

}  // namespace

std::optional<image::Range> reach_within(std::uint8_t code,
                                         std::span<const std::uint8_t> data,
                                         const image::Layout& layout,
                                         const image::Range& scope) noexcept {
    switch (code) {
        case 0x42: {
            if (data.empty()) return std::nullopt;
            const NameParse p = parse_name(data.subspan(1));
            if (p.error != Error::None) return std::nullopt;
            return within(devices(p.name, 1, layout), scope);
        }
        case 0x43:
        case 0x44:
        case 0x45:
        case 0x46:
        case 0x47: {
            const Head h = read_head(data);
            if (h.error != Error::None) return std::nullopt;
            // 00 is 256 discretes (43-45); for registers it is refused, and so reaches nothing.
            const std::uint32_t n = h.count == 0 ? 256 : h.count;
            return within(devices(h.start, n, layout), scope);
        }
        case 0x48:
        case 0x49: {
            MixedItems items(data, code == 0x49);
            MixedItem item;
            while (items.next(item)) {
                if (auto r = within(devices(item.name, 1, layout), scope)) return r;
            }
            return std::nullopt;
        }
        default:
            return std::nullopt;
    }
}

}  // namespace plcemu::fatek
