#include "plcemu/config/config.hpp"

namespace plcemu::config {

void apply(const Overrides& overrides, Config& config) {
    if (overrides.port) config.modbus.tcp.port = *overrides.port;
    if (overrides.http_port) {
        // A config without `http:` (or with it turned off) gets the console with its defaults.
        if (!config.http) {
            config.http.emplace();
            config.http->bind = "127.0.0.1";
        }
        config.http->port = *overrides.http_port;
    }
    if (overrides.time_scale) config.time_scale = *overrides.time_scale;
}

}  // namespace plcemu::config
