#include "daemon.hpp"

#include <spdlog/spdlog.h>

#include <asio.hpp>

#include "plcemu/daemon/plc.hpp"
#include "daemon/scan_driver.hpp"
#include "modbus/tcp_server.hpp"

namespace plcemu::daemon {

void apply_overrides(config::Config& config, const Overrides& o) {
    if (o.port) config.modbus.tcp.port = *o.port;
    if (o.time_scale) config.time_scale = *o.time_scale;
}

namespace {

modbus::TcpOptions tcp_options(const config::Config& c) {
    modbus::TcpOptions o;
    o.bind = c.modbus.tcp.bind;
    o.port = c.modbus.tcp.port;
    o.max_clients = c.modbus.tcp.max_clients;
    o.idle_timeout_s = c.modbus.tcp.idle_timeout_s;
    for (const auto& a : c.modbus.tcp.allow) {
        modbus::Cidr cidr;
        if (!modbus::Cidr::parse(a, cidr)) {
            throw config::ConfigError({c.path, 0, 0}, "modbus.tcp.allow: bad CIDR '" + a + "'");
        }
        o.allow.push_back(cidr);
    }
    return o;
}

}  // namespace

int run_daemon(const std::string& config_path, const Overrides& overrides) {
    config::Config cfg = config::load_config(config_path);
    apply_overrides(cfg, overrides);
    spdlog::set_level(spdlog::level::from_str(cfg.log.level));

    Plc plc(cfg);
    asio::io_context io(1);

    std::unique_ptr<modbus::TcpServer> tcp;
    if (cfg.modbus.tcp.enabled) {
        tcp = std::make_unique<modbus::TcpServer>(io, plc.dispatcher(), tcp_options(cfg));
    }

    ScanDriver driver(io, plc.engine(), cfg.time_scale);

    spdlog::info("plcemud {}: profile {}, model {}, station {}, scan {} ms, time scale {}",
                 version(), image::profile_name(cfg.profile), cfg.model, int(cfg.station),
                 cfg.scan_ms, cfg.time_scale);
    spdlog::info("program: {} instruction(s)", cfg.program.size());
    if (tcp) spdlog::info("listening on tcp {}", tcp->endpoint());

    asio::signal_set signals(io, SIGINT, SIGTERM);
    signals.async_wait([&](const asio::error_code& ec, int sig) {
        if (ec) return;
        spdlog::info("signal {}: stopping", sig == SIGINT ? "SIGINT" : "SIGTERM");
        driver.stop();
        if (tcp) tcp->stop();
        io.stop();
    });

    driver.start();
    io.run();
    spdlog::info("stopped after {} scans", plc.engine().scans());
    return 0;
}

}  // namespace plcemu::daemon
