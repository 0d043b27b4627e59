// Kepware KEPServerEX tag CSV (docs/configuration.md, "Tag export"): the columns of the server's
// CSV import, addresses in the Modbus TCP/IP Ethernet driver's 6-digit decimal form.

#include "hmi_tags.hpp"

namespace plcemu::daemon {

namespace {

const char* kepware_type(const std::string& type) {
    if (type == "bool") return "Boolean";
    if (type == "uint16") return "Word";
    if (type == "int32") return "Long";
    return "Short";
}

// Kepware keeps a tag description to 255 characters; cut at a character boundary.
std::string description(std::string s) {
    constexpr std::size_t kMax = 255;
    if (s.size() <= kMax) return s;
    std::size_t n = kMax;
    while (n > 0 && (static_cast<unsigned char>(s[n]) & 0xC0) == 0x80) --n;
    s.resize(n);
    return s;
}

}  // namespace

void write_kepware(std::ostream& out, const std::vector<TagRow>& rows) {
    out << "Tag Name,Address,Data Type,Respect Data Type,Client Access,Scan Rate,Scaling,Raw Low,"
           "Raw High,Scaled Low,Scaled High,Scaled Data Type,Clamp Low,Clamp High,Eng Units,"
           "Description,Negate Value\r\n";
    for (const TagRow* r : hmi_rows(rows)) {
        // A `plcs:` entry's tags in a tag group named after it (a dot in a tag name is a group).
        const std::string name = r->plc.empty() ? r->device : hmi_device(*r) + "." + r->device;
        const std::string fields[] = {name,
                                      modbus_number(*r),
                                      kepware_type(r->type),
                                      "1",
                                      r->writable ? "R/W" : "RO",
                                      "100",
                                      "",
                                      "",
                                      "",
                                      "",
                                      "",
                                      "",
                                      "",
                                      "",
                                      "",
                                      description(r->description),
                                      ""};
        // Every field quoted, as the server's own export writes them.
        bool first = true;
        for (const auto& f : fields) {
            out << (first ? "" : ",") << csv_field(f, true);
            first = false;
        }
        out << "\r\n";
    }
}

}  // namespace plcemu::daemon
