#include "plcemu/modbus/dispatcher.hpp"

#include <spdlog/spdlog.h>

#include "plcemu/modbus/function_handler.hpp"

namespace plcemu::modbus {

Dispatcher::Dispatcher(Identity identity)
    : identity_(std::move(identity)),
      functions_(standard_functions()) {}

Dispatcher::~Dispatcher() = default;

std::size_t exception_pdu(std::uint8_t fc, Status s, PduBuffer out) noexcept {
    // Set the high bit rather than add 80h as modbus_reply_exception does, which would wrap
    // a function code of 80h or more to a normal-looking reply.
    out[0] = static_cast<std::uint8_t>(fc | 0x80);
    out[1] = static_cast<std::uint8_t>(s);
    return 2;
}

std::size_t Dispatcher::answer(const Request& r, PduBuffer out) noexcept {
    const std::uint8_t fc = r.pdu[0];
    auto exception = [&](Status s) -> std::size_t {
        // Refused requests are what a SCADA integrator hunts for; debug keeps them off by default.
        spdlog::debug("modbus: unit {} function {:02X}h address {} refused: exception {:02X}h{}",
                      r.slave_id, fc, r.pdu.size() >= 3 ? be16(r.pdu.data() + 1) : 0,
                      static_cast<unsigned>(s), r.broadcast ? " (broadcast, not sent)" : "");
        if (r.broadcast) return 0;  // a broadcast is never answered
        ++stats_.exceptions;
        return exception_pdu(fc, s, out);
    };

    ++stats_.requests;
    const FunctionHandler handler = fc < functions_.size() ? functions_[fc] : nullptr;
    if (handler == nullptr || !r.unit.serves(fc)) return exception(Status::IllegalFunction);
    const FunctionRequest request{r.pdu, r.unit, r.slave_id, r.broadcast, identity_};
    const FunctionReply reply = handler(request, out);
    if (reply.status != Status::Ok) return exception(reply.status);
    return r.broadcast ? 0 : reply.size;
}

void Dispatcher::set_function(std::uint8_t fc, FunctionHandler handler) {
    if (fc < functions_.size()) functions_[fc] = handler;
}

}  // namespace plcemu::modbus
