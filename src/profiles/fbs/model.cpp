#include "profiles/fbs/model.hpp"

#include <array>

#include "profiles/fatek/model.hpp"

namespace plcemu::profiles::fbs {

std::optional<std::uint16_t> model_code(std::string_view model) {
    static constexpr std::array<std::string_view, 3> kKinds{"MA", "MC", "MN"};
    static constexpr std::array kPoints{10, 14, 20, 24, 32, 40, 44, 60};
    return fatek::model_code(model, {"FBs-", kKinds, kPoints});
}

}  // namespace plcemu::profiles::fbs
