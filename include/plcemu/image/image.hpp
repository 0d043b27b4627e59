#pragma once
// The register image: every device area of the PLC in one block of memory.

#include <array>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <span>
#include <vector>

#include "plcemu/image/area.hpp"
#include "plcemu/image/layout.hpp"

namespace plcemu::image {

/// All device areas of one PLC, laid out in a single block. Bit areas store one byte per bit,
/// word areas one uint16_t per word, so a Modbus library can read and write them in place.
/// The block is owned (heap) or external (e.g. a memory-mapped state file), which is what makes
/// persistence a matter of where the block lives.
class Image {
public:
    /// An image with its own zeroed storage.
    explicit Image(Layout layout);
    /// An image over external storage of at least `storage_size(layout)` bytes, not cleared.
    Image(Layout layout, std::span<std::byte> storage);

    Image(const Image&) = delete;
    Image& operator=(const Image&) = delete;

    /// Bytes of storage a layout needs.
    static std::size_t storage_size(const Layout& layout);
    /// Byte offset of an area in the storage block.
    static std::size_t area_offset(const Layout& layout, Area a);
    /// Where a range's devices lie in the storage block (cut at the end of its area).
    struct Extent {
        std::size_t offset = 0;  ///< first byte
        std::size_t size = 0;    ///< bytes (0: the range holds no device of the area)
    };
    static Extent extent(const Layout& layout, const Range& r);

    /// The layout this image was built with.
    const Layout& layout() const { return layout_; }
    /// The storage block.
    std::span<std::byte> storage() { return storage_; }

    /// First byte of a bit area (one byte per bit).
    std::uint8_t* bits(Area a) { return reinterpret_cast<std::uint8_t*>(base(a)); }
    const std::uint8_t* bits(Area a) const {
        return reinterpret_cast<const std::uint8_t*>(base(a));
    }
    /// First word of a word area.
    std::uint16_t* words(Area a) { return reinterpret_cast<std::uint16_t*>(base(a)); }
    const std::uint16_t* words(Area a) const {
        return reinterpret_cast<const std::uint16_t*>(base(a));
    }

    /// Bit `i` of a bit area.
    bool bit(Area a, std::uint32_t i) const { return bits(a)[i] != 0; }
    /// Sets bit `i` of a bit area (not one hold() names, while it is set).
    void set_bit(Area a, std::uint32_t i, bool v) {
        if (held_ != nullptr && held(a, i)) return;
        bits(a)[i] = v ? 1 : 0;
    }
    /// Word `i` of a word area.
    std::uint16_t word(Area a, std::uint32_t i) const { return words(a)[i]; }
    /// Sets word `i` of a word area.
    void set_word(Area a, std::uint32_t i, std::uint16_t v) { words(a)[i] = v; }

    /// Reads a device operand as a word: a word device, 16 bits from a WMn-style operand, or a
    /// single bit as 0/1. Out-of-area indices read 0 (operands are checked at load).
    std::uint16_t read_word(const Device& d) const;
    /// Writes a word to a word device or to 16 bits of a WMn-style operand.
    void write_word(const Device& d, std::uint16_t v);
    /// Reads a bit device (a word device reads as "not zero").
    bool read_bit(const Device& d) const;
    /// Writes a bit device.
    void write_bit(const Device& d, bool v);

    /// One bit per discrete of each bit area (null for an area without any): the discretes a
    /// master disabled (engine::Holds).
    using HeldBits = std::array<const std::uint64_t*, kAreaCount>;
    /// While `held` is set (not null), set_bit(), write_bit() and write_word() leave the
    /// discretes it names as they are: the engine sets it for the program's part of a scan, so
    /// that a rung after an OUT to a disabled discrete (or a timer's or counter's contact) sees
    /// what the master put there.
    void hold(const HeldBits* held) noexcept { held_ = held; }

    /// Clears every device outside the given retentive ranges.
    void clear_non_retentive(const std::vector<Range>& retentive);
    /// Clears everything.
    void clear();

private:
    std::byte* base(Area a) const { return storage_.data() + offset_[static_cast<std::size_t>(a)]; }
    // Whether bit `i` of bit area `a` is held (held_ set).
    bool held(Area a, std::uint32_t i) const noexcept {
        const std::uint64_t* w = (*held_)[static_cast<std::size_t>(a)];
        return w != nullptr && ((w[i / 64] >> (i % 64)) & 1u) != 0;
    }

    Layout layout_;
    std::vector<std::byte> owned_;
    std::span<std::byte> storage_;
    std::array<std::size_t, kAreaCount> offset_{};
    const HeldBits* held_ = nullptr;
};

}  // namespace plcemu::image
