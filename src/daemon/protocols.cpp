#include "daemon/protocols.hpp"

#include <array>
#include <stdexcept>
#include <string>

#include "fatek/protocols.hpp"
#include "http/protocols.hpp"
#include "modbus_slave/protocols.hpp"

namespace plcemu::daemon {

std::span<const listener::ProtocolKind> protocols() {
    static const std::array kinds{modbus_slave::kModbusTcp, modbus_slave::kModbusRtu, fatek::kFatek,
                                  http::kHttp};
    return kinds;
}

const listener::ProtocolKind& protocol(std::string_view name) {
    for (const auto& k : protocols()) {
        if (k.name == name) return k;
    }
    throw std::logic_error("no protocol named " + std::string(name));
}

}  // namespace plcemu::daemon
