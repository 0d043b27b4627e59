#pragma once
// FB model names: "FB-<points><MA|MC>", e.g. FB-40MC (docs/profile-fb.md, "Identity").

#include <cstdint>
#include <optional>
#include <string_view>

namespace plcemu::profiles::fb {

/// The model code of R4167 for a model name: low byte I/O points, high byte 0 MA / 1 MC.
/// Returns nothing for a name that is not an FB model.
std::optional<std::uint16_t> model_code(std::string_view model);

}  // namespace plcemu::profiles::fb
