// FC 01–06, 0Fh, 10h, 16h: the unit resolves the addresses to a window onto its memory, and the
// request reads or writes that window in place.
//
// The replies are built here rather than by libmodbus' modbus_reply(): libmodbus 3.1 can only
// write a reply to a descriptor, and reading it back from a socket pair cost a third of the
// throughput at 16 connections (scripts/bench.sh: 59k against 92k requests/s). Each reply is a
// few lines of the Modbus application protocol; libmodbus stays the client in the interop tests.

#include <algorithm>

#include "plcemu/modbus/function_handler.hpp"

namespace plcemu::modbus::functions {

namespace {

// What a request asks for, once its format has been checked.
struct Access {
    Status status = Status::Ok;  // IllegalDataValue when malformed
    Table table = Table::HoldingRegisters;
    std::uint16_t addr = 0;
    std::uint16_t qty = 0;
    bool write = false;
};

bool in(std::uint16_t v, std::uint16_t lo, std::uint16_t hi) { return v >= lo && v <= hi; }

// Quantities and byte counts of the Modbus application protocol; a PDU of the wrong length is
// malformed (exception 03).
Access parse(const std::uint8_t* pdu, std::size_t n) {
    Access r;
    const std::uint8_t fc = pdu[0];
    auto bad = [&] {
        r.status = Status::IllegalDataValue;
        return r;
    };
    if (fc <= 0x06) {
        if (n != 5) return bad();
        r.addr = be16(pdu + 1);
        r.qty = be16(pdu + 3);
    }
    switch (fc) {
        case 0x01:
        case 0x02:
            r.table = fc == 0x01 ? Table::Coils : Table::DiscreteInputs;
            if (!in(r.qty, 1, 2000)) return bad();
            return r;
        case 0x03:
        case 0x04:
            r.table = fc == 0x03 ? Table::HoldingRegisters : Table::InputRegisters;
            if (!in(r.qty, 1, 125)) return bad();
            return r;
        case 0x05:
            r.table = Table::Coils;
            if (r.qty != 0x0000 && r.qty != 0xFF00) return bad();
            r.qty = 1;
            r.write = true;
            return r;
        case 0x06:
            r.table = Table::HoldingRegisters;
            r.qty = 1;
            r.write = true;
            return r;
        case 0x0F:
        case 0x10: {
            if (n < 6) return bad();
            r.addr = be16(pdu + 1);
            r.qty = be16(pdu + 3);
            r.write = true;
            const std::size_t bytes = pdu[5];
            if (fc == 0x0F) {
                r.table = Table::Coils;
                if (!in(r.qty, 1, 1968) || bytes != (r.qty + 7u) / 8u) return bad();
            } else {
                r.table = Table::HoldingRegisters;
                if (!in(r.qty, 1, 123) || bytes != r.qty * 2u) return bad();
            }
            if (n != 6 + bytes) return bad();
            return r;
        }
        default:  // 0x16, mask write register
            if (n != 7) return bad();
            r.table = Table::HoldingRegisters;
            r.addr = be16(pdu + 1);
            r.qty = 1;
            r.write = true;
            return r;
    }
}

}  // namespace

FunctionReply data_access(const FunctionRequest& req, PduBuffer out) noexcept {
    const std::uint8_t* pdu = req.pdu.data();
    const Access a = parse(pdu, req.pdu.size());
    const Span w = resolve_span(req.unit, a.table, a.addr, a.qty, a.write);
    // A table the unit does not serve outranks a malformed request (exception 01 before 03).
    if (w.status == Status::IllegalFunction) return FunctionReply::refuse(w.status);
    if (a.status != Status::Ok) return FunctionReply::refuse(a.status);
    if (w.status != Status::Ok) return FunctionReply::refuse(w.status);
    if (req.broadcast && !a.write) return FunctionReply::none();  // broadcast reads: ignored
    const std::uint8_t fc = pdu[0];
    std::size_t k = 0;
    out[k++] = fc;
    switch (fc) {
        case 0x01:
        case 0x02: {
            // Bits packed LSB first, one byte per 8 (the unit keeps one byte per bit).
            const std::size_t bytes = (a.qty + 7u) / 8u;
            out[k++] = static_cast<std::uint8_t>(bytes);
            std::fill_n(out.begin() + 2, bytes, std::uint8_t{0});
            for (std::size_t i = 0; i < a.qty; ++i) {
                if (w.bit(i))
                    out[2 + i / 8] = static_cast<std::uint8_t>(out[2 + i / 8] | 1u << (i % 8));
            }
            k += bytes;
            break;
        }
        case 0x03:
        case 0x04:
            out[k++] = static_cast<std::uint8_t>(a.qty * 2);
            for (std::size_t i = 0; i < a.qty; ++i) {
                const std::uint16_t v = w.word(i);
                out[k++] = static_cast<std::uint8_t>(v >> 8);
                out[k++] = static_cast<std::uint8_t>(v & 0xFF);
            }
            break;
        case 0x05:  // the reply echoes the request
            w.set_bit(0, be16(pdu + 3) == 0xFF00);
            std::copy_n(pdu + 1, 4, out.begin() + 1);
            k = 5;
            break;
        case 0x06:
            w.set_word(0, be16(pdu + 3));
            std::copy_n(pdu + 1, 4, out.begin() + 1);
            k = 5;
            break;
        case 0x0F:
            for (std::size_t i = 0; i < a.qty; ++i)
                w.set_bit(i, ((pdu[6 + i / 8] >> (i % 8)) & 1u) != 0);
            std::copy_n(pdu + 1, 4, out.begin() + 1);  // address and quantity
            k = 5;
            break;
        case 0x10:
            for (std::size_t i = 0; i < a.qty; ++i) w.set_word(i, be16(pdu + 6 + 2 * i));
            std::copy_n(pdu + 1, 4, out.begin() + 1);
            k = 5;
            break;
        default: {  // 0x16: (value AND and-mask) OR (or-mask AND NOT and-mask); echoes the request
            const std::uint16_t and_mask = be16(pdu + 3);
            const std::uint16_t or_mask = be16(pdu + 5);
            w.set_word(0,
                       static_cast<std::uint16_t>((w.word(0) & and_mask) | (or_mask & ~and_mask)));
            std::copy_n(pdu + 1, 6, out.begin() + 1);
            k = 7;
            break;
        }
    }
    if (a.write) req.unit.written(a.table, a.addr, a.qty);
    return FunctionReply::pdu(k);
}

}  // namespace plcemu::modbus::functions
