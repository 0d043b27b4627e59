#include "items.hpp"

#include "plcemu/listener/access.hpp"

namespace plcemu::fatek {

namespace {

// `n` consecutive bits from `first`, bit 0 the first.
std::uint32_t pack(const std::uint8_t* first, std::uint32_t n) {
    std::uint32_t v = 0;
    for (std::uint32_t i = 0; i < n; ++i) v |= static_cast<std::uint32_t>(first[i] & 1) << i;
    return v;
}

void unpack(std::uint8_t* first, std::uint32_t n, std::uint32_t v) {
    for (std::uint32_t i = 0; i < n; ++i) first[i] = static_cast<std::uint8_t>(v >> i & 1);
}

}  // namespace

std::uint32_t read_item(const image::Image& image, const Run& run, std::uint32_t k) noexcept {
    const std::uint32_t at = run.start + k * run.step;
    switch (run.form) {
        case Form::Discrete:
            return image.bits(run.area)[at] != 0 ? 1 : 0;
        case Form::Packed16:
        case Form::Packed32:
            return pack(image.bits(run.area) + at, run.step);
        case Form::Pair:
        case Form::Counter32: {
            const std::uint16_t* w = image.words(run.area) + at;
            return static_cast<std::uint32_t>(w[1]) << 16 | w[0];
        }
        default:
            return image.words(run.area)[at];
    }
}

void write_item(image::Image& image, const Run& run, std::uint32_t k, std::uint32_t v) noexcept {
    const std::uint32_t at = run.start + k * run.step;
    switch (run.form) {
        case Form::Discrete:
            image.bits(run.area)[at] = static_cast<std::uint8_t>(v & 1);
            break;
        case Form::Packed16:
        case Form::Packed32:
            unpack(image.bits(run.area) + at, run.step, v);
            break;
        case Form::Pair:
        case Form::Counter32: {
            std::uint16_t* w = image.words(run.area) + at;
            w[0] = static_cast<std::uint16_t>(v & 0xFFFF);
            w[1] = static_cast<std::uint16_t>(v >> 16);
            break;
        }
        default:
            image.words(run.area)[at] = static_cast<std::uint16_t>(v);
            break;
    }
}

bool writable(const Run& run,
              const std::vector<image::Range>* protected_ranges,
              const engine::Holds& holds) noexcept {
    return !listener::write_refused_by(protected_ranges, holds,
                                       {run.area, run.start, run.step * run.items});
}

}  // namespace plcemu::fatek
