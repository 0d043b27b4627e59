// FC 08, diagnostics: subfunction 00 (return query data) echoes the request; the others are not
// served (exception 01).

#include <algorithm>

#include "plcemu/modbus/function_handler.hpp"

namespace plcemu::modbus::functions {

FunctionReply diagnostics(const FunctionRequest& req, PduBuffer out) noexcept {
    const auto& pdu = req.pdu;
    if (pdu.size() < 3) return FunctionReply::refuse(Status::IllegalDataValue);
    if (be16(pdu.data() + 1) != 0) return FunctionReply::refuse(Status::IllegalFunction);
    std::copy(pdu.begin(), pdu.end(), out.begin());
    return FunctionReply::pdu(pdu.size());
}

}  // namespace plcemu::modbus::functions
