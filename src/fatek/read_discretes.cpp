// 43 (read the ENABLE/DISABLE flags of consecutive discretes: 1 disabled) and 44 (read the
// status of consecutive discretes): NN (1-256, 00 = 256) and the start discrete.

#include "command.hpp"
#include "head.hpp"
#include "items.hpp"

namespace plcemu::fatek::handlers {

namespace {

// Checks a 43/44 request; `run` is the discretes it reads.
Error check(std::span<const std::uint8_t> data, const Target& plc, Run& run) {
    const Head h = read_head(data);
    if (h.error != Error::None) return h.error;
    if (h.size != data.size()) return Error::Format;
    if (h.start.form != Form::Discrete) return Error::Address;
    return resolve(h.start, h.count == 0 ? 256 : h.count, plc.engine.image().layout(), run);
}

}  // namespace

Error read_disable_flags(std::span<const std::uint8_t> data, Target& plc, Reply& reply) noexcept {
    Run run;
    if (const Error e = check(data, plc, run); e != Error::None) return e;
    const engine::Holds& holds = plc.engine.holds();
    for (std::uint32_t k = 0; k < run.items; ++k) {
        reply.put(holds.held(run.area, run.start + k) ? '1' : '0');
    }
    return Error::None;
}

Error read_discretes(std::span<const std::uint8_t> data, Target& plc, Reply& reply) noexcept {
    Run run;
    if (const Error e = check(data, plc, run); e != Error::None) return e;
    const std::uint8_t* bits = plc.engine.image().bits(run.area) + run.start;
    for (std::uint32_t k = 0; k < run.items; ++k) reply.put(bits[k] != 0 ? '1' : '0');
    return Error::None;
}

}  // namespace plcemu::fatek::handlers
