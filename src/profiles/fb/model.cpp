#include "profiles/fb/model.hpp"

#include <array>

#include "profiles/fatek/model.hpp"

namespace plcemu::profiles::fb {

std::optional<std::uint16_t> model_code(std::string_view model) {
    static constexpr std::array<std::string_view, 2> kKinds{"MA", "MC"};
    // The FB main units' I/O points (docs/profile-fb.md, "Identity": a Decision, the seeds name
    // only the 40-point unit).
    static constexpr std::array kPoints{14, 20, 24, 28, 32, 40, 60};
    return fatek::model_code(model, {"FB-", kKinds, kPoints});
}

}  // namespace plcemu::profiles::fb
