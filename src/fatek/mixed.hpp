#pragma once
// What 48 and 49 share: a count NN and NN names (49: each followed by its value), any mix of
// discretes, 16-bit and 32-bit names, at most 64 of them weighing at most 64 words (a 32-bit name
// weighs 2) (docs/profile-fbs.md, "FATEK protocol", limits).

#include <cstdint>
#include <span>

#include "names.hpp"

namespace plcemu::fatek {

/// One item of a mixed request.
struct MixedItem {
    Name name;
    std::span<const std::uint8_t> value;  ///< 49 only: the value's characters
};

/// The items of a mixed request, read one after the other.
class MixedItems {
public:
    /// The items of `data` (after NN); with `values`, each name is followed by its value.
    MixedItems(std::span<const std::uint8_t> data, bool values) noexcept
        : data_(data),
          values_(values) {}
    /// The next item; false at the end or at an error (error() says which).
    bool next(MixedItem& item) noexcept;
    /// Format (a name or value that cannot be read), Address (a prefix the protocol does not
    /// have: nothing after it can be read), or None.
    Error error() const noexcept { return error_; }

private:
    std::span<const std::uint8_t> data_;
    bool values_;
    std::size_t at_ = 2;
    Error error_ = Error::None;
};

/// Checks a mixed request up to its addresses: format (4), then count and weight (2); then that
/// every name exists (A). `data` is the whole request data.
Error check_mixed(std::span<const std::uint8_t> data,
                  bool values,
                  const image::Layout& layout) noexcept;

}  // namespace plcemu::fatek
