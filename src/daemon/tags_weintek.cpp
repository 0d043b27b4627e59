// Weintek EasyBuilder Pro address tag library CSV (docs/configuration.md, "Tag export"): no
// header, one user-defined tag a line: name, device, address type, address, comment, data type.
// The MODBUS TCP/IP driver's address types are the tables' digits with an x (4x), and its
// addresses are 1-based.

#include "hmi_tags.hpp"

namespace plcemu::daemon {

namespace {

// A bit address type has no data type to choose.
const char* data_type(const std::string& type) {
    if (type == "bool") return "";
    if (type == "uint16") return "16-bit Unsigned";
    if (type == "int32") return "32-bit Signed";
    return "16-bit Signed";
}

}  // namespace

void write_weintek(std::ostream& out, const std::vector<TagRow>& rows) {
    for (const TagRow* r : hmi_rows(rows)) {
        // Names unique in the library: a `plcs:` entry's prefixed with its device and `_`.
        const std::string name = r->plc.empty() ? r->device : hmi_device(*r) + "_" + r->device;
        out << csv_field(name) << ',' << csv_field(hmi_device(*r)) << ',' << modbus_digit(r->table)
            << "x," << (r->address + 1) << ',' << csv_field(r->description) << ','
            << data_type(r->type) << "\r\n";
    }
}

}  // namespace plcemu::daemon
