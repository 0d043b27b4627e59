#include "profiles/vb/file_registers.hpp"

#include "plcemu/profiles/profile.hpp"
#include "profiles/vb/blocks.hpp"

namespace plcemu::profiles::vb {

std::optional<image::Range> file_registers(const config::Config& config) {
    for (const auto& [name, node] : config.sections) {
        if (name != "file_registers" || node.is_null()) continue;
        const config::Reader r(profiles::of(config).naming());
        const image::Range range = r.range(node, "file_registers");
        // FX2N keeps its file registers in D1000–D7999; the VB's general and latched D are the
        // whole choice here, the special D9000–D9255 are not program data.
        if (range.area != image::Area::D || range.end() > kBlockAreaEnd) {
            r.fail(node, "file_registers: expected a range of D0-D7999 such as D1000-D1099, got '" +
                             image::excerpt(node.text) + "'");
        }
        return range;
    }
    return std::nullopt;
}

}  // namespace plcemu::profiles::vb
