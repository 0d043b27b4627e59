// FC 11h, report slave ID: the unit's ID, run indicator ON, and "VENDOR MODEL plcemu VERSION".

#include "plcemu/modbus/function_handler.hpp"

namespace plcemu::modbus::functions {

FunctionReply report_slave_id(const FunctionRequest& req, PduBuffer out) noexcept {
    if (req.pdu.size() != 1) return FunctionReply::refuse(Status::IllegalDataValue);
    const Identity& id = req.identity;
    std::size_t k = 0;
    out[k++] = 0x11;
    out[k++] = 0;  // byte count, filled below
    out[k++] = req.slave_id;
    out[k++] = 0xFF;  // run indicator: ON
    auto put = [&](const std::string& s) {
        for (char c : s) {
            if (k >= 250) return;
            out[k++] = static_cast<std::uint8_t>(c);
        }
    };
    put(id.vendor + " " + id.product + " plcemu " + id.revision);
    out[1] = static_cast<std::uint8_t>(k - 2);
    return FunctionReply::pdu(k);
}

}  // namespace plcemu::modbus::functions
