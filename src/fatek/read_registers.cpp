// 46: read consecutive registers: NN and the start register; the values follow in address
// order, 4 hex digits each (8 for the 32-bit names).

#include "command.hpp"
#include "items.hpp"
#include "registers.hpp"

namespace plcemu::fatek::handlers {

Error read_registers(std::span<const std::uint8_t> data, Target& plc, Reply& reply) noexcept {
    const Head h = read_head(data);
    if (h.error == Error::Format) return Error::Format;
    if (h.error == Error::None && h.size != data.size()) return Error::Format;
    Run run;
    if (const Error e = check_registers(h, plc.engine.image().layout(), run); e != Error::None) {
        return e;
    }
    const image::Image& image = plc.engine.image();
    if (run.form == Form::Register) {
        // The common case (R, D, RT, RC) straight from the words.
        const std::uint16_t* words = image.words(run.area) + run.start;
        for (std::uint32_t k = 0; k < run.items; ++k) reply.hex(words[k], 4);
        return Error::None;
    }
    const Width w = width_of(run.form);
    for (std::uint32_t k = 0; k < run.items; ++k) reply.value(w, read_item(image, run, k));
    return Error::None;
}

}  // namespace plcemu::fatek::handlers
