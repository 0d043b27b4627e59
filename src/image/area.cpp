#include "plcemu/image/area.hpp"

#include <algorithm>
#include <tuple>

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

namespace {

// The devices a list covers, as sorted, merged ranges.
std::vector<Range> merged(std::vector<Range> v) {
    std::sort(v.begin(), v.end(), [](const Range& a, const Range& b) {
        return std::tie(a.area, a.start) < std::tie(b.area, b.start);
    });
    std::vector<Range> out;
    for (const Range& r : v) {
        if (r.count == 0) continue;
        if (!out.empty() && out.back().area == r.area && r.start <= out.back().end()) {
            out.back().count = std::max(out.back().end(), r.end()) - out.back().start;
        } else {
            out.push_back(r);
        }
    }
    return out;
}

}  // namespace

bool same_devices(const std::vector<Range>& a, const std::vector<Range>& b) {
    return a == b || merged(a) == merged(b);
}

}  // namespace plcemu::image
