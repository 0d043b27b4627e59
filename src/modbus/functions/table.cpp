// The standard function-code table: one row and one handler per code.

#include "plcemu/modbus/function_handler.hpp"

namespace plcemu::modbus {

FunctionTable standard_functions() {
    FunctionTable t{};
    t[0x01] = &functions::read_coils;
    t[0x02] = &functions::read_discrete_inputs;
    t[0x03] = &functions::read_holding_registers;
    t[0x04] = &functions::read_input_registers;
    t[0x05] = &functions::write_single_coil;
    t[0x06] = &functions::write_single_register;
    t[0x08] = &functions::diagnostics;
    t[0x0F] = &functions::write_multiple_coils;
    t[0x10] = &functions::write_multiple_registers;
    t[0x11] = &functions::report_slave_id;
    t[0x16] = &functions::mask_write_register;
    t[0x17] = &functions::read_write_registers;
    t[0x2B] = &functions::device_identification;
    return t;
}

}  // namespace plcemu::modbus
