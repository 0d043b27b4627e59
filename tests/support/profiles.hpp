#pragma once
// The registered profiles as tests use them.

#include <optional>
#include <string_view>

#include "plcemu/image/layout.hpp"
#include "plcemu/image/naming.hpp"
#include "plcemu/profiles/profile.hpp"

namespace plcemu::testing {

/// A registered profile (the test fails loudly on a typo: the pointer is checked).
inline const profiles::Profile& profile(std::string_view name) {
    const profiles::Profile* p = profiles::find(name);
    if (p == nullptr) std::abort();
    return *p;
}

/// The FBs profile.
inline const profiles::Profile& fbs() { return profile("fbs"); }
/// The FBs layout.
inline image::Layout fbs_layout() { return fbs().layout(); }
/// The FBs device spelling.
inline const image::Naming& fbs_naming() { return fbs().naming(); }
/// An FBs device name parsed.
inline std::optional<image::Device> fbs_device(std::string_view text) {
    return fbs_naming().parse_device(text);
}

}  // namespace plcemu::testing
