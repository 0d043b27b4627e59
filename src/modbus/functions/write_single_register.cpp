// FC 06 write single register (Modbus application protocol 6.6); the reply echoes the request.

#include "access.hpp"

namespace plcemu::modbus::functions {

FunctionReply write_single_register(const FunctionRequest& r, PduBuffer out) noexcept {
    Access a = address_and_quantity(r, Table::HoldingRegisters);
    if (a.status == Status::Ok) {
        a.qty = 1;
        a.write = true;
    }
    Span w;
    if (auto refused = refusal(r, a, w)) return *refused;
    w.set_word(0, be16(r.pdu.data() + 3));
    return echo(r, a, 4, out);
}

}  // namespace plcemu::modbus::functions
