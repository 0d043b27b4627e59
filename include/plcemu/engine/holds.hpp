#pragma once
// Discretes a master has disabled (FATEK command 42, "disable"; docs/profile-fbs.md, "FATEK
// protocol"): neither the I/O refresh nor the program changes them any more, only a master does.
// The flags are volatile: a restart of the emulator clears them; RUN/STOP keeps them.

#include <array>
#include <cstdint>
#include <vector>

#include "plcemu/image/image.hpp"

namespace plcemu::engine {

/// The disabled discretes of one PLC.
class Holds {
public:
    /// Flags for every discrete of `layout`'s bit areas, all enabled.
    explicit Holds(const image::Layout& layout);
    /// A copy's bits() points into its own words.
    Holds(const Holds& other);
    Holds& operator=(const Holds& other);

    /// Disables (true) or enables (false) discrete `index` of bit area `area`; false when the
    /// discrete does not exist.
    bool set(image::Area area, std::uint32_t index, bool held) noexcept;
    /// True when the discrete is disabled (false for one that does not exist).
    bool held(image::Area area, std::uint32_t index) const noexcept;
    /// True when no discrete is disabled.
    bool empty() const noexcept { return count_ == 0; }
    /// Enables every discrete.
    void clear() noexcept;

    /// Takes the values the disabled discretes have now (a scan's start: what a master left).
    void take(const image::Image& image) noexcept;
    /// Puts the values taken back (after the I/O refresh and after the program).
    void put(image::Image& image) const noexcept;
    /// The disabled flags, for image::Image::hold() while the program runs.
    const image::Image::HeldBits& bits() const noexcept { return view_; }

private:
    // One bit a discrete of each bit area: disabled or not, and its value at the last take().
    // 5,000 PLCs of an FBs hold 2 × 4,000 bits each here; a record per discrete that may be
    // disabled took 52 KB a PLC, half the process's memory. The words are all there from the
    // start: nothing is allocated on the request path.
    struct Bits {
        std::vector<std::uint64_t> held;
        std::vector<std::uint64_t> value;
        std::uint32_t size = 0;  // discretes in the area
    };
    // Calls `f(area, index)` for each disabled discrete.
    template <class F>
    void each_held(F f) const;
    // Points view_ at areas_'s words.
    void point() noexcept;

    std::array<Bits, image::kAreaCount> areas_;
    image::Image::HeldBits view_{};  // areas_[a].held.data(), null for a word area
    std::uint32_t count_ = 0;
};

}  // namespace plcemu::engine
