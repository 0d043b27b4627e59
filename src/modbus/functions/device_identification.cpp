// FC 2Bh/0Eh, read device identification: VendorName, ProductCode, MajorMinorRevision and
// ModelName, basic and regular categories, stream and individual access.

#include <algorithm>
#include <array>
#include <cstring>
#include <string>

#include "plcemu/modbus/function_handler.hpp"

namespace plcemu::modbus::functions {

FunctionReply device_identification(const FunctionRequest& req, PduBuffer out) noexcept {
    const std::uint8_t* pdu = req.pdu.data();
    const std::size_t n = req.pdu.size();
    constexpr std::uint8_t kReadDeviceId = 0x0E;
    if (n < 2 || pdu[1] != kReadDeviceId) return FunctionReply::refuse(Status::IllegalFunction);
    if (n != 4) return FunctionReply::refuse(Status::IllegalDataValue);
    const std::uint8_t code = pdu[2];
    std::uint8_t object = pdu[3];
    if (code < 1 || code > 4) return FunctionReply::refuse(Status::IllegalDataValue);
    struct Object {
        std::uint8_t id;
        const std::string* value;
    };
    const Identity& ident = req.identity;
    const std::array<Object, 4> objects{{{0x00, &ident.vendor},
                                         {0x01, &ident.product},
                                         {0x02, &ident.revision},
                                         {0x05, &ident.product}}};  // ModelName: the model too
    const std::uint8_t last_id = code == 1 ? 0x02 : 0x7F;
    auto known = [&](std::uint8_t id) {
        for (const auto& o : objects) {
            if (o.id == id) return true;
        }
        return false;
    };
    if (code == 4 && !known(object)) return FunctionReply::refuse(Status::IllegalDataAddress);
    if (code != 4 && (!known(object) || object > last_id)) object = 0;
    std::size_t k = 0;
    out[k++] = 0x2B;
    out[k++] = kReadDeviceId;
    out[k++] = code;
    out[k++] = 0x82;  // conformity: regular identification, stream and individual
    out[k++] = 0x00;  // more follows: no (everything fits in one PDU)
    out[k++] = 0x00;  // next object id
    const std::size_t count_at = k++;
    std::uint8_t count = 0;
    for (const auto& o : objects) {
        if (code == 4 ? o.id != object : (o.id < object || o.id > last_id)) continue;
        if (k + 2 > out.size()) break;
        // Each value is cut to what is left of the PDU (a very long model name).
        const std::size_t room = out.size() - k - 2;
        const std::size_t len = std::min<std::size_t>({o.value->size(), room, 255});
        out[k++] = o.id;
        out[k++] = static_cast<std::uint8_t>(len);
        std::memcpy(out.data() + k, o.value->data(), len);
        k += len;
        ++count;
    }
    out[count_at] = count;
    return FunctionReply::pdu(k);
}

}  // namespace plcemu::modbus::functions
