#include "plcemu/engine/holds.hpp"

#include <algorithm>
#include <bit>

namespace plcemu::engine {

namespace {

constexpr std::uint32_t kWord = 64;

std::uint64_t mask_of(std::uint32_t index) { return std::uint64_t{1} << (index % kWord); }

}  // namespace

Holds::Holds(const image::Layout& layout) {
    for (std::size_t a = 0; a < image::kAreaCount; ++a) {
        if (!image::is_bit_area(static_cast<image::Area>(a))) continue;
        Bits& b = areas_[a];
        b.size = layout.size[a];
        b.held.assign((b.size + kWord - 1) / kWord, 0);
        b.value.assign(b.held.size(), 0);
    }
    point();
}

Holds::Holds(const Holds& other)
    : areas_(other.areas_),
      count_(other.count_) {
    point();
}

Holds& Holds::operator=(const Holds& other) {
    areas_ = other.areas_;
    count_ = other.count_;
    point();
    return *this;
}

void Holds::point() noexcept {
    for (std::size_t a = 0; a < image::kAreaCount; ++a)
        view_[a] = areas_[a].held.empty() ? nullptr : areas_[a].held.data();
}

bool Holds::set(image::Area area, std::uint32_t index, bool held) noexcept {
    Bits& b = areas_[static_cast<std::size_t>(area)];
    if (index >= b.size) return false;
    std::uint64_t& word = b.held[index / kWord];
    if (((word & mask_of(index)) != 0) == held) return true;
    word ^= mask_of(index);
    if (held) {
        b.value[index / kWord] &= ~mask_of(index);  // as a record's value began: 0
        ++count_;
    } else {
        --count_;
    }
    return true;
}

bool Holds::held(image::Area area, std::uint32_t index) const noexcept {
    const Bits& b = areas_[static_cast<std::size_t>(area)];
    return index < b.size && (b.held[index / kWord] & mask_of(index)) != 0;
}

void Holds::clear() noexcept {
    for (auto& b : areas_) {
        std::fill(b.held.begin(), b.held.end(), std::uint64_t{0});
        std::fill(b.value.begin(), b.value.end(), std::uint64_t{0});
    }
    count_ = 0;
}

template <class F>
void Holds::each_held(F f) const {
    if (count_ == 0) return;
    for (std::size_t a = 0; a < image::kAreaCount; ++a) {
        const Bits& b = areas_[a];
        for (std::size_t w = 0; w < b.held.size(); ++w) {
            for (std::uint64_t m = b.held[w]; m != 0; m &= m - 1) {
                f(static_cast<image::Area>(a), static_cast<std::uint32_t>(w * kWord) +
                                                   static_cast<std::uint32_t>(std::countr_zero(m)));
            }
        }
    }
}

void Holds::take(const image::Image& image) noexcept {
    each_held([&](image::Area area, std::uint32_t i) {
        std::uint64_t& word = areas_[static_cast<std::size_t>(area)].value[i / kWord];
        word = image.bits(area)[i] != 0 ? word | mask_of(i) : word & ~mask_of(i);
    });
}

void Holds::put(image::Image& image) const noexcept {
    each_held([&](image::Area area, std::uint32_t i) {
        const Bits& b = areas_[static_cast<std::size_t>(area)];
        image.bits(area)[i] = (b.value[i / kWord] & mask_of(i)) != 0 ? 1 : 0;
    });
}

}  // namespace plcemu::engine
