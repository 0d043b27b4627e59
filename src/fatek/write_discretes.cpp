// 45: write consecutive discretes: NN (1-256, 00 = 256), the start discrete and exactly NN
// characters 0/1.

#include "command.hpp"
#include "head.hpp"
#include "items.hpp"

namespace plcemu::fatek::handlers {

Error write_discretes(std::span<const std::uint8_t> data, Target& plc, Reply&) noexcept {
    const Head h = read_head(data);
    if (h.error == Error::Format) return Error::Format;
    const std::uint32_t items = h.count == 0 ? 256 : h.count;
    if (h.error == Error::None && data.size() != h.size + items) return Error::Format;
    if (h.error == Error::None) {
        for (std::size_t i = h.size; i < data.size(); ++i) {
            if (data[i] != '0' && data[i] != '1') return Error::Value;
        }
    }
    if (h.error != Error::None || h.start.form != Form::Discrete) return Error::Address;
    Run run;
    if (resolve(h.start, items, plc.engine.image().layout(), run) != Error::None) {
        return Error::Address;
    }
    if (plc.read_only || !writable(run, plc.protected_ranges, plc.engine.holds())) {
        return Error::WriteDisabled;
    }
    std::uint8_t* bits = plc.engine.image().bits(run.area) + run.start;
    for (std::uint32_t k = 0; k < items; ++k) {
        bits[k] = data[h.size + k] == '1' ? 1 : 0;
    }
    return Error::None;
}

}  // namespace plcemu::fatek::handlers
