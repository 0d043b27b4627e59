#include "profiles/fb/controlled_points.hpp"

namespace plcemu::profiles::fb {

void ControlledPoints::claim(instructions::Operands& ops,
                             const char* key,
                             std::string_view mnemonic,
                             long long first,
                             long long count,
                             const std::string& where) {
    for (long long p = first; p < first + count; ++p) {
        if (p < 0 || p >= Points::kCount) continue;
        const std::string& other = by_[static_cast<std::size_t>(p)];
        if (!other.empty()) {
            ops.fail(key, "point " + std::to_string(p) + " is already controlled by " + other +
                              " (two instructions may not control the same point)");
        }
    }
    const std::string me = "the " + std::string(mnemonic) + " at " + where;
    for (long long p = first; p < first + count; ++p) {
        if (p >= 0 && p < Points::kCount) by_[static_cast<std::size_t>(p)] = me;
    }
}

}  // namespace plcemu::profiles::fb
