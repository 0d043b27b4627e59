#include "plcemu/engine/holds.hpp"

#include <algorithm>

namespace plcemu::engine {

Holds::Holds(const image::Layout& layout) {
    for (std::size_t a = 0; a < image::kAreaCount; ++a) {
        if (image::is_bit_area(static_cast<image::Area>(a))) flags_[a].resize(layout.size[a]);
    }
    // Every discrete may be disabled: bits_ never grows on the request path.
    std::size_t total = 0;
    for (const auto& f : flags_) total += f.size();
    bits_.reserve(total);
}

bool Holds::set(image::Area area, std::uint32_t index, bool held) noexcept {
    auto& f = flags_[static_cast<std::size_t>(area)];
    if (index >= f.size()) return false;
    if ((f[index] != 0) == held) return true;
    f[index] = held ? 1 : 0;
    if (held) {
        bits_.push_back({area, index, 0});  // within the capacity reserved above
        ++count_;
    } else {
        std::erase_if(bits_, [&](const Bit& b) { return b.area == area && b.index == index; });
        --count_;
    }
    return true;
}

bool Holds::held(image::Area area, std::uint32_t index) const noexcept {
    const auto& f = flags_[static_cast<std::size_t>(area)];
    return index < f.size() && f[index] != 0;
}

void Holds::clear() noexcept {
    for (auto& f : flags_) std::fill(f.begin(), f.end(), std::uint8_t{0});
    bits_.clear();
    count_ = 0;
}

void Holds::take(const image::Image& image) noexcept {
    for (auto& b : bits_) b.value = image.bits(b.area)[b.index];
}

void Holds::put(image::Image& image) const noexcept {
    for (const auto& b : bits_) image.bits(b.area)[b.index] = b.value;
}

}  // namespace plcemu::engine
