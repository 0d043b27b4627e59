#pragma once
// The writer of a FATEK reply, in place in the listener's buffer: STX, station, command, the
// data a handler writes, checksum, ETX (FBs manual, Appendix 2 FATEK Communication Protocol).

#include <cstddef>
#include <cstdint>

#include "checksum.hpp"
#include "frame.hpp"
#include "hex.hpp"
#include "names.hpp"

namespace plcemu::fatek {

/// A reply being written into a buffer of at least kMaxFrame bytes.
class Reply {
public:
    /// Starts the reply of `station` to `command` (its two characters as received) at `out`.
    Reply(std::uint8_t* out, std::uint8_t station, const std::uint8_t* command) noexcept
        : begin_(out),
          at_(out) {
        put(kStx);
        hex(station, 2);
        for (int i = 0; i < 2; ++i) {
            const std::uint8_t c = command[i];
            put(c >= 'a' && c <= 'z' ? static_cast<std::uint8_t>(c - 'a' + 'A') : c);
        }
    }

    /// Appends one character.
    void put(std::uint8_t c) noexcept { *at_++ = c; }
    /// Appends `v` as `digits` upper-case hex digits.
    void hex(std::uint32_t v, int digits) noexcept { at_ = put_hex(at_, v, digits); }
    /// Appends an item's value: `0`/`1`, 4 or 8 hex digits.
    void value(Width w, std::uint32_t v) noexcept {
        if (w == Width::Bit) {
            put(v != 0 ? '1' : '0');
        } else {
            hex(v, w == Width::Word ? 4 : 8);
        }
    }
    /// Bytes written so far.
    std::size_t size() const noexcept { return static_cast<std::size_t>(at_ - begin_); }
    /// Drops what was written after the first `n` bytes.
    void truncate(std::size_t n) noexcept { at_ = begin_ + n; }
    /// Appends the checksum and ETX; returns the reply's size.
    std::size_t finish() noexcept {
        hex(checksum({begin_, size()}), 2);
        put(kEtx);
        return size();
    }

private:
    std::uint8_t* begin_;
    std::uint8_t* at_;
};

}  // namespace plcemu::fatek
