#include "access.hpp"

#include <algorithm>

namespace plcemu::modbus::functions {

Access address_and_quantity(const FunctionRequest& r, Table table) {
    if (r.pdu.size() != 5) return malformed({});
    return {Status::Ok, table, be16(r.pdu.data() + 1), be16(r.pdu.data() + 3), false};
}

std::optional<FunctionReply> refusal(const FunctionRequest& r, const Access& a, Span& w) noexcept {
    w = resolve_span(r.unit, a.table, a.addr, a.qty, a.write);
    // A table the unit does not serve outranks a malformed request (exception 01 before 03).
    if (w.status == Status::IllegalFunction) return FunctionReply::refuse(w.status);
    if (a.status != Status::Ok) return FunctionReply::refuse(a.status);
    if (w.status != Status::Ok) return FunctionReply::refuse(w.status);
    if (r.broadcast && !a.write) return FunctionReply::none();  // broadcast reads: ignored
    return std::nullopt;
}

FunctionReply echo(const FunctionRequest& r, const Access& a, std::size_t n, PduBuffer out) {
    r.unit.written(a.table, a.addr, a.qty);
    std::copy_n(r.pdu.begin(), n + 1, out.begin());
    return FunctionReply::pdu(n + 1);
}

}  // namespace plcemu::modbus::functions
