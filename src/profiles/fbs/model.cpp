#include "profiles/fbs/model.hpp"

#include <array>
#include <charconv>

namespace plcemu::profiles::fbs {

std::optional<std::uint16_t> model_code(std::string_view model) {
    constexpr std::string_view kPrefix = "FBs-";
    if (model.substr(0, kPrefix.size()) != kPrefix || model.size() < 7) return std::nullopt;
    const std::string_view kind = model.substr(model.size() - 2);
    const std::string_view digits = model.substr(4, model.size() - 6);
    int hi = -1;
    if (kind == "MA") hi = 0;
    if (kind == "MC") hi = 1;
    if (kind == "MN") hi = 2;
    if (hi < 0 || digits.empty() || digits.size() > 2) return std::nullopt;
    int points = 0;
    const auto [end, ec] = std::from_chars(digits.data(), digits.data() + digits.size(), points);
    if (ec != std::errc{} || end != digits.data() + digits.size()) return std::nullopt;
    constexpr std::array kPoints{10, 14, 20, 24, 32, 40, 44, 60};
    for (int p : kPoints) {
        if (p == points) return static_cast<std::uint16_t>(hi << 8 | points);
    }
    return std::nullopt;
}

}  // namespace plcemu::profiles::fbs
