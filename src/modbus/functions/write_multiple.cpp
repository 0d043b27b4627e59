// FC 0Fh write multiple coils, FC 10h write multiple registers (Modbus application protocol
// 6.11, 6.12): address, quantity, byte count and the values; the byte count must match the
// quantity and the PDU's length. The reply echoes the address and quantity.

#include "access.hpp"

namespace plcemu::modbus::functions {

namespace {

// Address, quantity and byte count, checked against `max` and `bytes_for(quantity)`.
template <typename BytesFor>
Access parse(const FunctionRequest& r, Table table, std::uint16_t max, BytesFor bytes_for) {
    const std::size_t n = r.pdu.size();
    if (n < 6) return malformed({});
    const std::uint8_t* pdu = r.pdu.data();
    const Access a{Status::Ok, table, be16(pdu + 1), be16(pdu + 3), true};
    const std::size_t bytes = pdu[5];
    if (!in(a.qty, 1, max) || bytes != bytes_for(a.qty)) return malformed(a);
    if (n != 6 + bytes) return malformed(a);
    return a;
}

}  // namespace

FunctionReply write_multiple_coils(const FunctionRequest& r, PduBuffer out) noexcept {
    const Access a =
        parse(r, Table::Coils, kMaxWriteBits, [](std::uint16_t q) { return (q + 7u) / 8u; });
    Span w;
    if (auto refused = refusal(r, a, w)) return *refused;
    for (std::size_t i = 0; i < a.qty; ++i) w.set_bit(i, ((r.pdu[6 + i / 8] >> (i % 8)) & 1u) != 0);
    return echo(r, a, 4, out);
}

FunctionReply write_multiple_registers(const FunctionRequest& r, PduBuffer out) noexcept {
    const Access a = parse(r, Table::HoldingRegisters, kMaxWriteRegisters,
                           [](std::uint16_t q) { return q * 2u; });
    Span w;
    if (auto refused = refusal(r, a, w)) return *refused;
    for (std::size_t i = 0; i < a.qty; ++i) w.set_word(i, be16(r.pdu.data() + 6 + 2 * i));
    return echo(r, a, 4, out);
}

}  // namespace plcemu::modbus::functions
