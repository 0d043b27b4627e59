#pragma once
// FBs model names: "FBs-<points><MA|MC|MN>", e.g. FBs-24MC (FBs manual, model table).

#include <cstdint>
#include <optional>
#include <string_view>

namespace plcemu::profiles::fbs {

/// The model code of R4167 for a model name: low byte I/O points, high byte 0 MA / 1 MC / 2 MN.
/// Returns nothing for a name that is not an FBs model.
std::optional<std::uint16_t> model_code(std::string_view model);

}  // namespace plcemu::profiles::fbs
