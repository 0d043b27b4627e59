#pragma once
// The comparisons of two signed words as the manuals write them (=, <>, <, <=, >, >=), shared
// by CMPOUT and the comparison contacts of a listing.

#include <array>
#include <cstdint>
#include <optional>
#include <string_view>
#include <utility>

namespace plcemu::instructions {

/// A comparison.
enum class Relation : std::uint8_t { Eq, Ne, Lt, Le, Gt, Ge };

/// The comparisons as the manuals write them.
inline constexpr std::array<std::pair<std::string_view, Relation>, 6> kRelations{
    {{"=", Relation::Eq},
     {"<>", Relation::Ne},
     {"<", Relation::Lt},
     {"<=", Relation::Le},
     {">", Relation::Gt},
     {">=", Relation::Ge}}};

/// The comparison written `text`, if it is one.
inline std::optional<Relation> relation_of(std::string_view text) {
    for (const auto& [name, r] : kRelations) {
        if (text == name) return r;
    }
    return std::nullopt;
}

/// `a` `r` `b`, both signed.
inline bool holds(Relation r, std::int16_t a, std::int16_t b) noexcept {
    switch (r) {
        case Relation::Eq:
            return a == b;
        case Relation::Ne:
            return a != b;
        case Relation::Lt:
            return a < b;
        case Relation::Le:
            return a <= b;
        case Relation::Gt:
            return a > b;
        case Relation::Ge:
            return a >= b;
    }
    return false;
}

}  // namespace plcemu::instructions
