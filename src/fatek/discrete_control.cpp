// 42: single discrete control. 1 disables the discrete (only a master changes it then), 2
// enables it, 3 sets it, 4 resets it (docs/profile-fbs.md, "FATEK protocol").

#include "command.hpp"
#include "items.hpp"

namespace plcemu::fatek::handlers {

Error discrete_control(std::span<const std::uint8_t> data, Target& plc, Reply&) noexcept {
    if (data.empty()) return Error::Format;
    const NameParse p = parse_name(data.subspan(1));
    if (p.error == Error::Format) return Error::Format;
    if (p.error == Error::None && p.name.length != data.size() - 1) return Error::Format;
    const std::uint8_t code = data[0];
    if (code < '1' || code > '4') return Error::Value;
    if (p.error != Error::None || p.name.form != Form::Discrete) return Error::Address;
    Run run;
    if (resolve(p.name, 1, plc.engine.image().layout(), run) != Error::None) return Error::Address;
    if (plc.read_only) return Error::WriteDisabled;
    switch (code) {
        case '1':
        case '2':
            plc.engine.holds().set(run.area, run.start, code == '1');
            break;
        default:
            if (!writable(run, plc.protected_ranges, plc.engine.holds())) {
                return Error::WriteDisabled;
            }
            write_item(plc.engine.image(), run, 0, code == '3' ? 1 : 0);
            break;
    }
    return Error::None;
}

}  // namespace plcemu::fatek::handlers
