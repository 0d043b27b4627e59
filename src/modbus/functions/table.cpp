// The standard function-code table: one row per code, one handler per code or family.

#include "plcemu/modbus/function_handler.hpp"

namespace plcemu::modbus {

FunctionTable standard_functions() {
    FunctionTable t{};
    for (int fc : {0x01, 0x02, 0x03, 0x04, 0x05, 0x06, 0x0F, 0x10, 0x16}) {
        t[static_cast<std::size_t>(fc)] = &functions::data_access;
    }
    t[0x08] = &functions::diagnostics;
    t[0x11] = &functions::report_slave_id;
    t[0x17] = &functions::read_write_registers;
    t[0x2B] = &functions::device_identification;
    return t;
}

}  // namespace plcemu::modbus
