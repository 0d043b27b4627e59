#include "profiles/fatek/layout.hpp"

#include "profiles/fatek/special_registers.hpp"

namespace plcemu::profiles::fatek {

image::Layout make_layout(std::uint32_t family, std::string_view name, std::uint32_t d_words) {
    using image::Area;
    image::Layout l;
    l.family = family;
    l.family_name = name;
    l.set_size(Area::X, 256);
    l.set_size(Area::Y, 256);
    l.set_size(Area::M, 2002);
    l.set_size(Area::S, 1000);
    l.set_size(Area::T, 256);
    l.set_size(Area::C, 256);
    // R0–R8071 as one array: R4168–R4999 exist on no FATEK PLC and are never mapped, but one
    // array keeps the R numbers equal to indices. They are a hole: no protocol, operand or
    // config range reaches them.
    l.set_size(Area::R, 8072);
    l.holes = {{Area::R, 4168, 5000 - 4168}};
    l.set_size(Area::D, d_words);
    l.set_size(Area::TV, 256);
    // C0–C199 one word each, C200–C255 two words each (low word first).
    l.set_size(Area::CV, 200 + 56 * 2);
    // The FBs manual's default retentive ranges (docs/profile-fbs.md).
    l.retentive = {
        {Area::M, 800, 600},
        {Area::S, 500, 500},
        {Area::R, 0, 3000},
        {Area::D, 0, d_words},
        {Area::R, 5000, 3072},
        {Area::CV, 100, 40},
        {Area::CV, 200, 80},  // C200–C239, two words each
        {Area::R, special::kPowerUps, 1},
    };
    return l;
}

}  // namespace plcemu::profiles::fatek
