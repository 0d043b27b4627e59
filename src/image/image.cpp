#include "plcemu/image/image.hpp"

#include <algorithm>
#include <cstring>

namespace plcemu::image {

namespace {

constexpr std::size_t kAlign = 64;

// Bytes one device of the area takes: a byte per bit, two per word.
std::size_t device_bytes(Area a) { return is_bit_area(a) ? 1 : 2; }

std::size_t bytes_of(const Layout& l, Area a) {
    return static_cast<std::size_t>(l.size_of(a)) * device_bytes(a);
}

std::size_t align_up(std::size_t n) { return (n + kAlign - 1) / kAlign * kAlign; }

}  // namespace

std::size_t Image::area_offset(const Layout& layout, Area a) {
    std::size_t off = 0;
    for (std::size_t i = 0; i < static_cast<std::size_t>(a); ++i) {
        off += align_up(bytes_of(layout, static_cast<Area>(i)));
    }
    return off;
}

Image::Extent Image::extent(const Layout& layout, const Range& r) {
    const std::uint32_t n = layout.size_of(r.area);
    if (r.start >= n) return {};
    const std::size_t width = device_bytes(r.area);
    const std::uint64_t end = std::min<std::uint64_t>(std::uint64_t{r.start} + r.count, n);
    return {area_offset(layout, r.area) + r.start * width,
            static_cast<std::size_t>(end - r.start) * width};
}

std::size_t Image::storage_size(const Layout& layout) {
    return area_offset(layout, static_cast<Area>(kAreaCount - 1)) +
           align_up(bytes_of(layout, static_cast<Area>(kAreaCount - 1)));
}

Image::Image(Layout layout)
    : layout_(std::move(layout)),
      owned_(storage_size(layout_)),
      storage_(owned_) {
    for (std::size_t i = 0; i < kAreaCount; ++i) {
        offset_[i] = area_offset(layout_, static_cast<Area>(i));
    }
}

Image::Image(Layout layout, std::span<std::byte> storage)
    : layout_(std::move(layout)),
      storage_(storage.first(storage_size(layout_))) {
    for (std::size_t i = 0; i < kAreaCount; ++i) {
        offset_[i] = area_offset(layout_, static_cast<Area>(i));
    }
}

std::uint16_t Image::read_word(const Device& d) const {
    const std::uint32_t n = layout_.size_of(d.area);
    if (d.word_of_bits) {
        std::uint16_t v = 0;
        for (std::uint32_t b = 0; b < 16 && d.index + b < n; ++b) {
            v = static_cast<std::uint16_t>(v | (bits(d.area)[d.index + b] ? 1u << b : 0u));
        }
        return v;
    }
    if (d.index >= n) return 0;
    if (is_bit_area(d.area)) return bits(d.area)[d.index] ? 1 : 0;
    return words(d.area)[d.index];
}

void Image::write_word(const Device& d, std::uint16_t v) {
    const std::uint32_t n = layout_.size_of(d.area);
    if (d.word_of_bits) {
        for (std::uint32_t b = 0; b < 16 && d.index + b < n; ++b) {
            if (held_ != nullptr && held(d.area, d.index + b)) continue;
            bits(d.area)[d.index + b] = (v >> b) & 1u;
        }
        return;
    }
    if (d.index >= n) return;
    if (is_bit_area(d.area)) {
        if (held_ != nullptr && held(d.area, d.index)) return;
        bits(d.area)[d.index] = v ? 1 : 0;
    } else {
        words(d.area)[d.index] = v;
    }
}

bool Image::read_bit(const Device& d) const {
    if (d.index >= layout_.size_of(d.area)) return false;
    if (is_bit_area(d.area)) return bits(d.area)[d.index] != 0;
    return words(d.area)[d.index] != 0;
}

void Image::write_bit(const Device& d, bool v) {
    if (d.index >= layout_.size_of(d.area)) return;
    if (is_bit_area(d.area)) {
        if (held_ != nullptr && held(d.area, d.index)) return;
        bits(d.area)[d.index] = v ? 1 : 0;
    } else {
        words(d.area)[d.index] = v ? 1 : 0;
    }
}

void Image::clear_non_retentive(const std::vector<Range>& retentive) {
    for (std::size_t i = 0; i < kAreaCount; ++i) {
        const Area a = static_cast<Area>(i);
        const std::uint32_t n = layout_.size_of(a);
        std::vector<bool> keep(n, false);
        for (const auto& r : retentive) {
            if (r.area != a) continue;
            for (std::uint32_t k = r.start; k < r.end() && k < n; ++k) keep[k] = true;
        }
        for (std::uint32_t k = 0; k < n; ++k) {
            if (keep[k]) continue;
            if (is_bit_area(a)) {
                bits(a)[k] = 0;
            } else {
                words(a)[k] = 0;
            }
        }
    }
}

void Image::clear() { std::memset(storage_.data(), 0, storage_.size()); }

}  // namespace plcemu::image
