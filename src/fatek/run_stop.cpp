// 41: RUN (1) or STOP (0). The emulator always starts, so the "cannot RUN" codes 5, 6, 7 and 9
// never come (docs/profile-fbs.md, "FATEK protocol").

#include "command.hpp"

namespace plcemu::fatek::handlers {

Error run_stop(std::span<const std::uint8_t> data, Target& plc, Reply&) noexcept {
    if (data.size() != 1) return Error::Format;
    if (data[0] != '0' && data[0] != '1') return Error::Value;
    if (plc.read_only) return Error::WriteDisabled;
    plc.engine.set_running(data[0] == '1');
    return Error::None;
}

}  // namespace plcemu::fatek::handlers
