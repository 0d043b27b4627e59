#pragma once
// FATEK model names: "<prefix><points><kind>", e.g. FBs-24MC or FB-40MC, and the model code of
// R4167 they give.

#include <cstdint>
#include <optional>
#include <span>
#include <string_view>

namespace plcemu::profiles::fatek {

/// What a family's model names may be.
struct ModelGrammar {
    std::string_view prefix;                  ///< "FBs-"
    std::span<const std::string_view> kinds;  ///< in code order: "MA" 0, "MC" 1, …
    std::span<const int> points;              ///< the main units' I/O points
};

/// The model code of R4167 for a model name: low byte I/O points, high byte the kind's position
/// in `grammar.kinds` (0 MA, 1 MC, 2 MN). Returns nothing for a name outside the grammar.
std::optional<std::uint16_t> model_code(std::string_view model, const ModelGrammar& grammar);

}  // namespace plcemu::profiles::fatek
