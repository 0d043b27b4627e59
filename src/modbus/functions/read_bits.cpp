// FC 01 read coils, FC 02 read discrete inputs (Modbus application protocol 6.1, 6.2): the bits
// packed LSB first, one byte per 8 (the unit keeps one byte per bit).

#include <algorithm>

#include "access.hpp"

namespace plcemu::modbus::functions {

namespace {

FunctionReply read_bits(const FunctionRequest& r, Table table, PduBuffer out) noexcept {
    Access a = address_and_quantity(r, table);
    if (a.status == Status::Ok && !in(a.qty, 1, kMaxReadBits)) a = malformed(a);
    Span w;
    if (auto refused = refusal(r, a, w)) return *refused;
    const std::size_t bytes = (a.qty + 7u) / 8u;
    out[0] = r.pdu[0];
    out[1] = static_cast<std::uint8_t>(bytes);
    std::fill_n(out.begin() + 2, bytes, std::uint8_t{0});
    for (std::size_t i = 0; i < a.qty; ++i) {
        if (w.bit(i)) out[2 + i / 8] = static_cast<std::uint8_t>(out[2 + i / 8] | 1u << (i % 8));
    }
    return FunctionReply::pdu(2 + bytes);
}

}  // namespace

FunctionReply read_coils(const FunctionRequest& r, PduBuffer out) noexcept {
    return read_bits(r, Table::Coils, out);
}

FunctionReply read_discrete_inputs(const FunctionRequest& r, PduBuffer out) noexcept {
    return read_bits(r, Table::DiscreteInputs, out);
}

}  // namespace plcemu::modbus::functions
