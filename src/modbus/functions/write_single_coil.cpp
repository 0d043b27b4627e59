// FC 05 write single coil (Modbus application protocol 6.5): FF00h sets, 0000h clears, any
// other value is malformed; the reply echoes the request.

#include "access.hpp"

namespace plcemu::modbus::functions {

FunctionReply write_single_coil(const FunctionRequest& r, PduBuffer out) noexcept {
    Access a = address_and_quantity(r, Table::Coils);
    if (a.status == Status::Ok) {
        if (a.qty != 0x0000 && a.qty != 0xFF00) {
            a = malformed(a);
        } else {
            a.qty = 1;
            a.write = true;
        }
    }
    Span w;
    if (auto refused = refusal(r, a, w)) return *refused;
    w.set_bit(0, be16(r.pdu.data() + 3) == 0xFF00);
    return echo(r, a, 4, out);
}

}  // namespace plcemu::modbus::functions
