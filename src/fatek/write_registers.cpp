// 47: write consecutive registers: NN, the start register and NN values of its width.

#include "command.hpp"
#include "items.hpp"
#include "registers.hpp"

namespace plcemu::fatek::handlers {

Error write_registers(std::span<const std::uint8_t> data, Target& plc, Reply&) noexcept {
    const Head h = read_head(data);
    if (h.error == Error::Format) return Error::Format;
    const std::size_t chars = chars_of(register_width(h));
    const std::size_t items = h.count == 0 ? 256 : h.count;
    if (h.error == Error::None) {
        if (data.size() != h.size + items * chars) return Error::Format;
        for (std::size_t i = h.size; i < data.size(); ++i) {
            if (hex_digit(data[i]) < 0) return Error::Format;
        }
    }
    Run run;
    if (const Error e = check_registers(h, plc.engine.image().layout(), run); e != Error::None) {
        return e;
    }
    if (plc.read_only || !writable(run, plc.protected_ranges, plc.engine.holds())) {
        return Error::WriteDisabled;
    }
    image::Image& image = plc.engine.image();
    for (std::uint32_t k = 0; k < run.items; ++k) {
        const auto v = parse_hex(data.subspan(h.size + k * chars, chars));
        write_item(image, run, k, v.value_or(0));
    }
    return Error::None;
}

}  // namespace plcemu::fatek::handlers
