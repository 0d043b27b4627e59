#include "plcemu/image/area.hpp"

namespace plcemu::image {

std::string_view area_name(Area a) {
    switch (a) {
        case Area::X:
            return "X";
        case Area::Y:
            return "Y";
        case Area::M:
            return "M";
        case Area::S:
            return "S";
        case Area::T:
            return "T";
        case Area::C:
            return "C";
        case Area::R:
            return "R";
        case Area::D:
            return "D";
        case Area::TV:
            return "TV";
        case Area::CV:
            return "CV";
    }
    return "?";
}

}  // namespace plcemu::image
