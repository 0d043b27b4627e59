#include "profiles/fb/shared_devices.hpp"

#include <cstdint>
#include <string>
#include <string_view>

#include "profiles/fb/module_cycle.hpp"
#include "profiles/fb/special_registers.hpp"

namespace plcemu::profiles::fb {

namespace {

bool writes(const engine::Claim& c) { return c.kind != engine::ClaimKind::Read; }

// Why `mine` may not overlap `other`'s devices: both write them, or one writes the other's
// settings.
std::string why(const engine::Claim& mine, const engine::Claim& other) {
    if (!writes(mine)) return " (it writes them, and this instruction reads them as settings)";
    if (!writes(other)) return " (it reads them as settings, and this instruction writes them)";
    return " (two instructions may not write the same devices)";
}

}  // namespace

void claim_bit(std::vector<std::pair<const char*, engine::Claim>>& mine,
               const char* key,
               const std::optional<image::Device>& bit,
               std::string_view mnemonic,
               const std::string& where) {
    if (!bit) return;
    mine.push_back({key, {{bit->area, bit->index, 1}, engine::ClaimKind::Output, mnemonic, where}});
}

std::vector<engine::Claim> refuse_shared(
    instructions::Operands& ops, const std::vector<std::pair<const char*, engine::Claim>>& mine) {
    // Within the instruction: a block it writes may hold none of its other operands.
    for (std::size_t i = 0; i < mine.size(); ++i) {
        const engine::Claim& a = mine[i].second;
        for (std::size_t j = 0; j < i; ++j) {
            const engine::Claim& b = mine[j].second;
            if ((writes(a) || writes(b)) && a.range.overlaps(b.range)) {
                ops.fail(mine[i].first, ops.format(a.range) + " overlaps its own " + mine[j].first +
                                            " " + ops.format(b.range));
            }
        }
    }
    // Across the program: each pair is checked once, at the later entry.
    for (const auto& [key, claim] : mine) {
        for (const engine::Claim& c : ops.context().earlier.claims) {
            if (!claim.range.overlaps(c.range) || !(writes(claim) || writes(c))) continue;
            if (std::string_view(key) == "sm") {
                const std::uint32_t first = claim.range.start - special::kRawReadings;
                ops.fail(key, "points " + std::to_string(first) + "-" +
                                  std::to_string(first + cycle::kPoints - 1) +
                                  " are already measured by the " + std::string(c.mnemonic) +
                                  " at " + c.where);
            }
            ops.fail(key, ops.format(claim.range) + " overlaps " + ops.format(c.range) +
                              " of the " + std::string(c.mnemonic) + " at " + c.where +
                              why(claim, c));
        }
    }
    std::vector<engine::Claim> claims;
    claims.reserve(mine.size() + 1);
    for (const auto& c : mine) claims.push_back(c.second);
    return claims;
}

}  // namespace plcemu::profiles::fb
