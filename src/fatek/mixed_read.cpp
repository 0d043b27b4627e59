// 48: mixed read of random discretes and registers: one value per name, in order.

#include "command.hpp"
#include "items.hpp"
#include "mixed.hpp"

namespace plcemu::fatek::handlers {

Error mixed_read(std::span<const std::uint8_t> data, Target& plc, Reply& reply) noexcept {
    const image::Image& image = plc.engine.image();
    if (const Error e = check_mixed(data, false, image.layout()); e != Error::None) return e;
    MixedItems items(data, false);
    MixedItem it;
    while (items.next(it)) {
        Run run;
        resolve(it.name, 1, image.layout(), run);
        reply.value(width_of(run.form), read_item(image, run, 0));
    }
    return Error::None;
}

}  // namespace plcemu::fatek::handlers
