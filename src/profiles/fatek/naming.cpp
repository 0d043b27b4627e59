#include "profiles/fatek/naming.hpp"

namespace plcemu::profiles::fatek {

image::Naming make_naming() {
    using image::Area;
    image::Naming n;
    // Longest prefixes first so that "TMR" wins over "T" and "CTR" over "C".
    n.prefixes = {{"TMR", Area::TV}, {"CTR", Area::CV}, {"X", Area::X}, {"Y", Area::Y},
                  {"M", Area::M},    {"S", Area::S},    {"T", Area::T}, {"C", Area::C},
                  {"R", Area::R},    {"D", Area::D}};
    n.names = {"X", "Y", "M", "S", "T", "C", "R", "D", "TMR", "CTR"};
    n.radix.fill(10);
    // C0–C199 take one word each, C200–C255 two (low word first).
    n.first_32bit_counter = 200;
    return n;
}

}  // namespace plcemu::profiles::fatek
