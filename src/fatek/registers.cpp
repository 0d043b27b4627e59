#include "registers.hpp"

namespace plcemu::fatek {

Error check_registers(const Head& h, const image::Layout& layout, Run& run) noexcept {
    const std::uint32_t limit = register_width(h) == Width::Dword ? kMaxWords / 2 : kMaxWords;
    if (h.count == 0 || h.count > limit) return Error::Value;
    if (h.error != Error::None || h.start.form == Form::Discrete) return Error::Address;
    return resolve(h.start, h.count, layout, run);
}

}  // namespace plcemu::fatek
