// A request's memory as consecutive windows: a request may run across map rows whose devices do
// not continue each other (D7999 at 7999, D9000 at 8000 on a VB), and is still served whole.

#include "plcemu/modbus/function_handler.hpp"

namespace plcemu::modbus {

Span resolve_span(
    Unit& unit, Table table, std::uint16_t addr, std::uint16_t qty, bool write) noexcept {
    Span s;
    std::uint32_t done = 0;
    while (done < qty) {
        if (s.n == Span::kMaxParts) {
            s.status = Status::IllegalDataAddress;
            return s;
        }
        const auto left = static_cast<std::uint16_t>(qty - done);
        const Window w = unit.resolve(table, static_cast<std::uint16_t>(addr + done), left, write);
        if (w.status != Status::Ok) {
            // A table the unit does not serve answers 01 only for the request as a whole.
            s.status = done == 0 ? w.status : Status::IllegalDataAddress;
            return s;
        }
        s.parts[s.n] = w;
        s.first[s.n] = static_cast<std::uint16_t>(done);
        ++s.n;
        done += w.count == 0 ? left : w.count;
    }
    s.status = Status::Ok;
    return s;
}

}  // namespace plcemu::modbus
