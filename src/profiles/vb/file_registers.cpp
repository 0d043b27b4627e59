#include "profiles/vb/file_registers.hpp"

#include "plcemu/image/excerpt.hpp"
#include "profiles/vb/blocks.hpp"

namespace plcemu::profiles::vb {

image::Range read_file_registers(const config::Reader& r, const config::Node& section) {
    const image::Range range = r.range(section, "file_registers");
    // FX2N keeps its file registers in D1000–D7999; the VB's general and latched D are the
    // whole choice here, the special D9000–D9255 are not program data.
    if (range.area != image::Area::D || range.end() > kBlockAreaEnd) {
        r.fail(section, "file_registers: expected a range of D0-D7999 such as D1000-D1099, got '" +
                            image::excerpt(section.text) + "'");
    }
    return range;
}

}  // namespace plcemu::profiles::vb
