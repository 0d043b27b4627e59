// plcemud: command line and the one top-level catch.

#include <spdlog/sinks/stdout_color_sinks.h>
#include <spdlog/spdlog.h>

#include <algorithm>
#include <csignal>
#include <cstdlib>
#include <iostream>
#include <string>
#include <vector>

#include "daemon.hpp"
#include "plcemu/daemon/plc.hpp"
#include "plcemu/profiles/profile.hpp"
#include "export_tags.hpp"
#include "log_format.hpp"
#include "parent_watch.hpp"
#include "print_map.hpp"

namespace {

constexpr int kExitBadConfig = 2;

const char* kUsage =
    "Usage: plcemud -c FILE [options]\n"
    "Emulates a PLC as a Modbus TCP/RTU slave.\n\n"
    "  -c, --config FILE    configuration file (YAML)\n"
    "      --check-config   validate the configuration and exit (0 valid, 2 invalid)\n"
    "      --print-map      print the Modbus address map and exit\n"
    "      --print-program  print each PLC's program with its step numbers and exit\n"
    "      --format FMT     with --print-map: text (default) or csv\n"
    "      --export-tags FMT  write one tag per device the configuration gives meaning to, as\n"
    "                       csv, json, kepware, ignition or weintek, and exit (needs -c)\n"
    "      --port N         override modbus.tcp.port\n"
    "      --http-port N    serve the console and REST API on port N (every PLC's http:, or\n"
    "                       127.0.0.1:N where a config has none)\n"
    "      --time-scale X   override time_scale (simulated seconds per real second)\n"
    "      --version        print the version and exit\n"
    "  -h, --help           print this help and exit\n";

// "Profiles: fbs (FATEK FBs), vb (VIGOR VB), fb (FATEK FB)".
std::string profile_list() {
    std::string s = "Profiles:";
    for (const auto* p : plcemu::profiles::all()) {
        s += (s.size() > 9 ? ", " : " ") + std::string(p->name()) + " (" + std::string(p->title()) +
             ")";
    }
    return s + "\n";
}

// The map --print-map shows without a config: the first family's (number 0), whatever the
// profiles' names sort as.
const plcemu::profiles::Profile& default_profile() {
    const auto all = plcemu::profiles::all();
    return **std::min_element(all.begin(), all.end(), [](const auto* a, const auto* b) {
        return a->family() < b->family();
    });
}

int usage_error(const std::string& msg) {
    std::cerr << "plcemud: " << msg << "\n" << kUsage;
    return kExitBadConfig;
}

// The configs as the start would take them: read, and every PLC built off-line (its program
// bound, operands and presets checked), so what the start refuses (exit status 2) is refused
// by --check-config, --print-map and --print-program too, not described.
std::vector<plcemu::config::Config> load_checked(const std::string& path,
                                                 const plcemu::config::Overrides& overrides) {
    std::vector<plcemu::config::Config> plcs = plcemu::config::load_plcs(path, overrides);
    plcemu::daemon::probe_all(plcs);
    return plcs;
}

}  // namespace

int main(int argc, char** argv) {
    // A reader of stderr that goes away (`plcemud | tee`, a log shipper restarting) must not
    // kill the PLC: writes to it fail with EPIPE instead, and so do sends to a vanished client.
    std::signal(SIGPIPE, SIG_IGN);
    auto logger = spdlog::stderr_color_mt("plcemud");
    spdlog::set_default_logger(logger);
    spdlog::set_formatter(plcemu::daemon::log_formatter());

    std::string config_path;
    bool check = false;
    bool print = false;
    bool show_program = false;
    bool csv = false;
    std::string tags;  // --export-tags: the format's name
    plcemu::daemon::TagFormat tag_format = plcemu::daemon::TagFormat::Csv;
    plcemu::config::Overrides overrides;
    for (int i = 1; i < argc; ++i) {
        const std::string a = argv[i];
        auto value = [&](std::string& out) {
            if (i + 1 >= argc) return false;
            out = argv[++i];
            return true;
        };
        std::string v;
        if (a == "-h" || a == "--help") {
            const auto& d = default_profile();
            std::cout << kUsage << '\n'
                      << profile_list() << "Without -c, --print-map shows the map of profile "
                      << d.name() << " (" << d.title() << ").\n";
            return 0;
        } else if (a == "--version") {
            std::cout << "plcemud " << plcemu::daemon::version() << "\n";
            return 0;
        } else if (a == "-c" || a == "--config") {
            if (!value(config_path)) return usage_error(a + " needs a file");
        } else if (a == "--check-config") {
            check = true;
        } else if (a == "--print-map") {
            print = true;
        } else if (a == "--print-program") {
            show_program = true;
        } else if (a == "--export-tags") {
            if (!value(tags) || !plcemu::daemon::parse_tag_format(tags, tag_format))
                return usage_error("--export-tags takes csv, json, kepware, ignition or weintek");
        } else if (a == "--format") {
            if (!value(v) || (v != "csv" && v != "text"))
                return usage_error("--format takes text or csv");
            csv = v == "csv";
        } else if (a == "--port") {
            char* end = nullptr;
            if (!value(v)) return usage_error("--port needs a number");
            const long p = std::strtol(v.c_str(), &end, 10);
            if (*end != '\0' || p < 0 || p > 65535) return usage_error("--port: 0..65535");
            overrides.port = static_cast<std::uint16_t>(p);
        } else if (a == "--http-port") {
            char* end = nullptr;
            if (!value(v)) return usage_error("--http-port needs a number");
            const long p = std::strtol(v.c_str(), &end, 10);
            if (*end != '\0' || p < 0 || p > 65535) return usage_error("--http-port: 0..65535");
            overrides.http_port = static_cast<std::uint16_t>(p);
        } else if (a == "--time-scale") {
            char* end = nullptr;
            if (!value(v)) return usage_error("--time-scale needs a number");
            const double x = std::strtod(v.c_str(), &end);
            if (*end != '\0' || !(x >= 0.001 && x <= 100000))
                return usage_error("--time-scale: 0.001..100000");
            overrides.time_scale = x;
        } else {
            return usage_error("unknown argument '" + a + "'");
        }
    }

    try {
        if (print) {
            const std::vector<plcemu::config::Config> plcs =
                config_path.empty()
                    ? plcemu::config::parse_plcs(
                          "profile: " + std::string(default_profile().name()) + "\n", "<built-in>")
                    : load_checked(config_path, overrides);
            // Several PLCs: one map after another, each headed by the PLC it is.
            for (std::size_t i = 0; i < plcs.size(); ++i) {
                if (i > 0) std::cout << '\n';
                plcemu::daemon::print_map(std::cout, plcs[i], csv);
            }
            return 0;
        }
        if (config_path.empty()) {
            return usage_error(!tags.empty() ? "--export-tags needs a configuration file (-c FILE)"
                               : show_program
                                   ? "--print-program needs a configuration file (-c FILE)"
                                   : "no configuration file (-c FILE)");
        }
        if (show_program) {
            const auto plcs = load_checked(config_path, overrides);
            for (std::size_t i = 0; i < plcs.size(); ++i) {
                if (plcs.size() > 1) {
                    std::cout << (i > 0 ? "\n" : "") << "# " << plcs[i].label << "\n";
                }
                std::cout << plcemu::daemon::print_program(plcs[i]);
            }
            return 0;
        }
        if (!tags.empty()) {
            // Every PLC of a `plcs:` file, each row saying which and where (docs/configuration.md,
            // "Tag export").
            const auto e =
                plcemu::daemon::export_tags(plcemu::config::load_plcs(config_path, overrides));
            plcemu::daemon::write_tags(std::cout, e.rows, tag_format);
            // Devices the configuration names that no Modbus address serves (a modbus.map that
            // leaves them out) are said on stderr: an import cannot reach them.
            for (const auto& u : e.unreachable)
                spdlog::warn("export-tags: no Modbus address for {}", u);
            return 0;
        }
        if (check) {
            // The start's own reading: what it would refuse, this refuses.
            const std::vector<plcemu::config::Config> plcs = load_checked(config_path, overrides);
            for (const auto& cfg : plcs) {
                if (!cfg.label.empty()) {
                    std::cout << config_path << ": " << cfg.label << ": ok, profile " << cfg.profile
                              << ", station " << int(cfg.station) << "\n";
                }
            }
            std::cout << config_path << ": ok\n";
            return 0;
        }
        if (!plcemu::daemon::watch_parent()) return 0;
        return plcemu::daemon::run_daemon(config_path, overrides);
    } catch (const plcemu::config::ConfigError& e) {
        // Every error the config has, one per line (docs/configuration.md, "Configuration").
        for (const auto& line : e.lines()) spdlog::error("config: {}", line);
        return kExitBadConfig;
    } catch (const std::exception& e) {
        spdlog::error("{}", e.what());
        return 1;
    }
}
