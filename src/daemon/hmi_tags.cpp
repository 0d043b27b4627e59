#include "hmi_tags.hpp"

#include <cctype>
#include <cstdio>

namespace plcemu::daemon {

std::string hmi_device(const TagRow& row) {
    if (row.plc.empty()) return "plcemu";
    std::string d = row.plc;
    for (char& c : d) {
        if (!std::isalnum(static_cast<unsigned char>(c)) && c != '_' && c != '-') c = '_';
    }
    return d;
}

std::vector<const TagRow*> hmi_rows(const std::vector<TagRow>& rows) {
    std::vector<const TagRow*> out;
    for (const auto& r : rows) {
        if (!r.device.empty()) out.push_back(&r);
    }
    return out;
}

char modbus_digit(modbus::Table table) {
    switch (table) {
        case modbus::Table::Coils:
            return '0';
        case modbus::Table::DiscreteInputs:
            return '1';
        case modbus::Table::InputRegisters:
            return '3';
        case modbus::Table::HoldingRegisters:
            break;
    }
    return '4';
}

std::string modbus_number(const TagRow& row) {
    char buf[8];
    std::snprintf(buf, sizeof buf, "%c%05u", modbus_digit(row.table),
                  static_cast<unsigned>(row.address) + 1);
    return buf;
}

}  // namespace plcemu::daemon
