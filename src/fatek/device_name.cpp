#include "plcemu/fatek/device_name.hpp"

#include <cstdio>

namespace plcemu::fatek {

namespace {

// FATEK's 32-bit counters start at C200; each takes two words of the counter values, low first.
constexpr std::uint32_t kFirstCounter32 = 200;

std::string name(const char* prefix, std::uint32_t number, int digits) {
    if (number >= (digits == 4 ? 10000u : 100000u)) return {};
    char buf[16];
    std::snprintf(buf, sizeof buf, "%s%0*u", prefix, digits, number);
    return buf;
}

}  // namespace

std::string device_name(image::Area area, std::uint32_t index, bool word_of_bits) {
    using image::Area;
    if (image::is_bit_area(area)) {
        static constexpr const char* kBits[] = {"X", "Y", "M", "S", "T", "C"};
        static constexpr const char* kWords[] = {"WX", "WY", "WM", "WS", "WT", "WC"};
        const auto a = static_cast<std::size_t>(area);
        if (!word_of_bits) return name(kBits[a], index, 4);
        return index % 8 == 0 ? name(kWords[a], index, 4) : std::string();
    }
    switch (area) {
        case Area::R:
            return name("R", index, 5);
        case Area::D:
            return name("D", index, 5);
        case Area::TV:
            return name("RT", index, 4);
        case Area::CV:
            if (index < kFirstCounter32) return name("RC", index, 4);
            if ((index - kFirstCounter32) % 2 != 0) return {};
            return name("DRC", kFirstCounter32 + (index - kFirstCounter32) / 2, 4);
        default:
            return {};
    }
}

}  // namespace plcemu::fatek
