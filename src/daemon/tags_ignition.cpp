// Ignition 8 tag JSON (docs/configuration.md, "Tag export"): OPC tags whose item paths use the
// Modbus TCP driver's addresses, unit-qualified ("[plcemu]1.HR101").

#include <string>

#include "hmi_tags.hpp"

namespace plcemu::daemon {

namespace {

// The driver's designator for the row's table and type: C, DI, HR/HRUS/HRI, IR/IRUS/IRI.
std::string designator(const TagRow& r) {
    switch (r.table) {
        case modbus::Table::Coils:
            return "C";
        case modbus::Table::DiscreteInputs:
            return "DI";
        case modbus::Table::HoldingRegisters:
        case modbus::Table::InputRegisters:
            break;
    }
    std::string d = r.table == modbus::Table::HoldingRegisters ? "HR" : "IR";
    if (r.type == "uint16") d += "US";
    if (r.type == "int32") d += "I";
    return d;
}

// Ignition's data types: an unsigned word needs Int4 to hold 65535.
const char* data_type(const std::string& type) {
    if (type == "bool") return "Boolean";
    if (type == "int16") return "Int2";
    return "Int4";
}

void atomic_tag(std::ostream& out, const TagRow& r, const char* indent) {
    const std::string path = "ns=1;s=[" + hmi_device(r) + "]" + std::to_string(r.unit) + "." +
                             designator(r) + std::to_string(r.address + 1);
    out << indent << "{\"name\": " << json_string(r.device)
        << ", \"tagType\": \"AtomicTag\", \"valueSource\": \"opc\", "
           "\"opcServer\": \"Ignition OPC UA Server\", \"opcItemPath\": "
        << json_string(path) << ", \"dataType\": \"" << data_type(r.type) << "\"";
    if (!r.writable) out << ", \"readOnly\": true";
    out << ", \"documentation\": " << json_string(r.description) << "}";
}

}  // namespace

void write_ignition(std::ostream& out, const std::vector<TagRow>& rows) {
    // A file holding one PLC: its tags at the top. A `plcs:` file: a folder per entry, named
    // as its device, so that the entries' tag names (the same devices) do not collide.
    const auto tags = hmi_rows(rows);
    out << "{\"tags\": [";
    std::string folder;
    bool first = true;
    for (const TagRow* r : tags) {
        if (!r->plc.empty() && hmi_device(*r) != folder) {
            if (!folder.empty()) out << "\n  ]}";
            folder = hmi_device(*r);
            out << (first ? "\n" : ",\n") << "  {\"name\": " << json_string(folder)
                << ", \"tagType\": \"Folder\", \"tags\": [\n";
            first = true;
        } else {
            out << (first ? "\n" : ",\n");
        }
        atomic_tag(out, *r, folder.empty() ? "  " : "    ");
        first = false;
    }
    if (!folder.empty()) out << "\n  ]}";
    out << (tags.empty() ? "]}\n" : "\n]}\n");
}

}  // namespace plcemu::daemon
