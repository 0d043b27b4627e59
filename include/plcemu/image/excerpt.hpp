#pragma once
// Text a user wrote (a value, a key, a device name, an operand) as an error message may quote it.
// It lives at the bottom layer because every module that reads what a user wrote (the image's
// device names, the instructions' operands, the config loader) quotes it the same way.

#include <cstddef>
#include <string>
#include <string_view>

namespace plcemu::image {

/// The text with control characters escaped (\n, \x1B, \u2028) so it cannot break or forge log
/// lines, and cut after `max_chars` characters with "…" so a pasted blob is never echoed whole.
std::string excerpt(std::string_view text, std::size_t max_chars = 40);

}  // namespace plcemu::image
