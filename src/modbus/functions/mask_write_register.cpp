// FC 16h mask write register (Modbus application protocol 6.16): the register becomes
// (value AND and-mask) OR (or-mask AND NOT and-mask); the reply echoes the request.

#include "access.hpp"

namespace plcemu::modbus::functions {

FunctionReply mask_write_register(const FunctionRequest& r, PduBuffer out) noexcept {
    const Access a = r.pdu.size() != 7 ? malformed({})
                                       : Access{Status::Ok, Table::HoldingRegisters,
                                                be16(r.pdu.data() + 1), 1, true};
    Span w;
    if (auto refused = refusal(r, a, w)) return *refused;
    const std::uint16_t and_mask = be16(r.pdu.data() + 3);
    const std::uint16_t or_mask = be16(r.pdu.data() + 5);
    w.set_word(0, static_cast<std::uint16_t>((w.word(0) & and_mask) | (or_mask & ~and_mask)));
    return echo(r, a, 6, out);
}

}  // namespace plcemu::modbus::functions
