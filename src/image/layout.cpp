#include "plcemu/image/layout.hpp"

#include <stdexcept>

namespace plcemu::image {

bool parse_profile(std::string_view text, Profile& out) {
    if (text == "fbs") {
        out = Profile::Fbs;
    } else if (text == "fb") {
        out = Profile::Fb;
    } else if (text == "vb") {
        out = Profile::Vb;
    } else {
        return false;
    }
    return true;
}

std::string_view profile_name(Profile p) {
    switch (p) {
        case Profile::Fbs:
            return "fbs";
        case Profile::Fb:
            return "fb";
        case Profile::Vb:
            return "vb";
    }
    return "?";
}

Layout fbs_layout() {
    Layout l;
    auto set = [&](Area a, std::uint32_t n) { l.size[static_cast<std::size_t>(a)] = n; };
    set(Area::X, 256);
    set(Area::Y, 256);
    set(Area::M, 2002);
    set(Area::S, 1000);
    set(Area::T, 256);
    set(Area::C, 256);
    // R0–R8071 as one array: R4168–R4999 exist on no FBs and are never mapped, but one array
    // keeps the R numbers equal to indices.
    set(Area::R, 8072);
    set(Area::D, 4000);
    set(Area::TV, 256);
    // C0–C199 one word each, C200–C255 two words each (low word first).
    set(Area::CV, 200 + 56 * 2);
    // SPEC §1: the FBs manual's default retentive ranges.
    l.retentive = {
        {Area::M, 800, 600},
        {Area::S, 500, 500},
        {Area::R, 0, 3000},
        {Area::D, 0, 4000},
        {Area::R, 5000, 3072},
        {Area::CV, 100, 40},
        {Area::CV, 200, 80},  // C200–C239, two words
                              // each
        {Area::R, 4057, 1},   // power-up counter
    };
    return l;
}

Layout layout_for(Profile p) {
    if (p == Profile::Fbs) return fbs_layout();
    throw std::invalid_argument("profile '" + std::string(profile_name(p)) +
                                "' is not supported yet (only 'fbs')");
}

}  // namespace plcemu::image
