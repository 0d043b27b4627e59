#include "config/fingerprint.hpp"

#include <algorithm>
#include <cstdint>
#include <string_view>

// Header-only (inlined), as the state file's page sums: a 128-bit sum leaves the chance that two
// different configs agree far below any other cause of a missed change.
#define XXH_INLINE_ALL
#include <xxhash.h>

namespace plcemu::config {

namespace {

class Summer {
public:
    Summer() { XXH3_128bits_reset(&state_); }

    void number(std::uint64_t v) { XXH3_128bits_update(&state_, &v, sizeof v); }
    // Its length first: "ab","c" and "a","bc" differ.
    void text(std::string_view s) {
        number(s.size());
        XXH3_128bits_update(&state_, s.data(), s.size());
    }
    // Kind, quoting and content; never the position.
    void node(const Node& n, bool skip_log = false) {
        number(static_cast<std::uint64_t>(n.kind) | (n.quoted ? 0x100U : 0U));
        text(n.text);
        number(n.items.size());
        for (const Node& item : n.items) node(item);
        const auto skipped = [&](const Node& key) {
            return skip_log && key.is_scalar() && key.text == "log";
        };
        number(static_cast<std::uint64_t>(std::count_if(
            n.entries.begin(), n.entries.end(), [&](const auto& e) { return !skipped(e.first); })));
        for (const auto& [key, value] : n.entries) {
            if (skipped(key)) continue;
            node(key);
            node(value);
        }
    }
    Fingerprint digest() const {
        const XXH128_hash_t h = XXH3_128bits_digest(&state_);
        return {h.low64, h.high64};
    }

private:
    XXH3_state_t state_{};
};

}  // namespace

Fingerprint fingerprint(const Config& config, const Node& root, const Node* shared_http) {
    Summer s;
    s.text(config.path);
    s.number(static_cast<std::uint64_t>(static_cast<std::int64_t>(config.index)));
    s.node(root, true);
    s.number(config.listing.size());
    for (const auto& line : config.listing) s.text(line.text);
    if (shared_http != nullptr) {
        s.number(1);
        s.node(*shared_http);
    } else {
        s.number(0);
    }
    return s.digest();
}

}  // namespace plcemu::config
