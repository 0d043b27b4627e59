// FC 03 read holding registers, FC 04 read input registers (Modbus application protocol 6.3,
// 6.4): two bytes per register, high byte first.

#include "access.hpp"

namespace plcemu::modbus::functions {

namespace {

FunctionReply read_registers(const FunctionRequest& r, Table table, PduBuffer out) noexcept {
    Access a = address_and_quantity(r, table);
    if (a.status == Status::Ok && !in(a.qty, 1, kMaxReadRegisters)) a = malformed(a);
    Span w;
    if (auto refused = refusal(r, a, w)) return *refused;
    out[0] = r.pdu[0];
    out[1] = static_cast<std::uint8_t>(a.qty * 2);
    for (std::size_t i = 0; i < a.qty; ++i) put_be16(out.data() + 2 + 2 * i, w.word(i));
    return FunctionReply::pdu(2 + 2 * std::size_t{a.qty});
}

}  // namespace

FunctionReply read_holding_registers(const FunctionRequest& r, PduBuffer out) noexcept {
    return read_registers(r, Table::HoldingRegisters, out);
}

FunctionReply read_input_registers(const FunctionRequest& r, PduBuffer out) noexcept {
    return read_registers(r, Table::InputRegisters, out);
}

}  // namespace plcemu::modbus::functions
