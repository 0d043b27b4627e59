// FC 17h, read/write multiple registers: the write is done first, then the read.

#include "plcemu/modbus/function_handler.hpp"

namespace plcemu::modbus::functions {

FunctionReply read_write_registers(const FunctionRequest& req, PduBuffer out) noexcept {
    const std::uint8_t* pdu = req.pdu.data();
    const std::size_t n = req.pdu.size();
    if (n < 10) return FunctionReply::refuse(Status::IllegalDataValue);
    const std::uint16_t raddr = be16(pdu + 1);
    const std::uint16_t rqty = be16(pdu + 3);
    const std::uint16_t waddr = be16(pdu + 5);
    const std::uint16_t wqty = be16(pdu + 7);
    const std::size_t bytes = pdu[9];
    const Span ww = resolve_span(req.unit, Table::HoldingRegisters, waddr, wqty, true);
    const Span rw = resolve_span(req.unit, Table::HoldingRegisters, raddr, rqty, false);
    if (ww.status == Status::IllegalFunction) return FunctionReply::refuse(Status::IllegalFunction);
    if (rqty < 1 || rqty > kMaxReadWriteRead || wqty < 1 || wqty > kMaxReadWriteWrite ||
        bytes != wqty * 2u || n != 10 + bytes) {
        return FunctionReply::refuse(Status::IllegalDataValue);
    }
    if (ww.status != Status::Ok) return FunctionReply::refuse(ww.status);
    if (rw.status != Status::Ok) return FunctionReply::refuse(rw.status);
    if (req.broadcast) return FunctionReply::none();  // has a read part: not a broadcast request
    for (std::size_t i = 0; i < wqty; ++i) ww.set_word(i, be16(pdu + 10 + 2 * i));
    req.unit.written(Table::HoldingRegisters, waddr, wqty);
    std::size_t k = 0;
    out[k++] = 0x17;
    out[k++] = static_cast<std::uint8_t>(rqty * 2);
    for (std::size_t i = 0; i < rqty; ++i) {
        const std::uint16_t v = rw.word(i);
        out[k++] = static_cast<std::uint8_t>(v >> 8);
        out[k++] = static_cast<std::uint8_t>(v & 0xFF);
    }
    return FunctionReply::pdu(k);
}

}  // namespace plcemu::modbus::functions
