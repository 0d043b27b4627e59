// 49: mixed write of random discretes and registers, each name followed by its value. Every
// item is checked before any is written: a refused request changes nothing.

#include "command.hpp"
#include "items.hpp"
#include "mixed.hpp"

namespace plcemu::fatek::handlers {

Error mixed_write(std::span<const std::uint8_t> data, Target& plc, Reply&) noexcept {
    image::Image& image = plc.engine.image();
    if (const Error e = check_mixed(data, true, image.layout()); e != Error::None) return e;
    if (plc.read_only) return Error::WriteDisabled;
    MixedItem it;
    Run run;
    MixedItems check(data, true);
    while (check.next(it)) {
        resolve(it.name, 1, image.layout(), run);
        if (!writable(run, plc.protected_ranges, plc.engine.holds())) return Error::WriteDisabled;
    }
    MixedItems items(data, true);
    while (items.next(it)) {
        resolve(it.name, 1, image.layout(), run);
        const std::uint32_t v = width_of(run.form) == Width::Bit ? (it.value[0] == '1' ? 1u : 0u)
                                                                 : parse_hex(it.value).value_or(0);
        write_item(image, run, 0, v);
    }
    return Error::None;
}

}  // namespace plcemu::fatek::handlers
