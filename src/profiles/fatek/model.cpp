#include "profiles/fatek/model.hpp"

#include <charconv>

namespace plcemu::profiles::fatek {

std::optional<std::uint16_t> model_code(std::string_view model, const ModelGrammar& grammar) {
    const std::string_view prefix = grammar.prefix;
    if (model.substr(0, prefix.size()) != prefix || model.size() < prefix.size() + 3) {
        return std::nullopt;
    }
    const std::string_view kind = model.substr(model.size() - 2);
    const std::string_view digits = model.substr(prefix.size(), model.size() - prefix.size() - 2);
    int hi = -1;
    int position = 0;
    for (std::string_view k : grammar.kinds) {
        if (k == kind) hi = position;
        ++position;
    }
    if (hi < 0 || digits.empty() || digits.size() > 2) return std::nullopt;
    int points = 0;
    const auto [end, ec] = std::from_chars(digits.data(), digits.data() + digits.size(), points);
    if (ec != std::errc{} || end != digits.data() + digits.size()) return std::nullopt;
    for (int p : grammar.points) {
        if (p == points) return static_cast<std::uint16_t>(hi << 8 | points);
    }
    return std::nullopt;
}

}  // namespace plcemu::profiles::fatek
