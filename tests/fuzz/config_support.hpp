#pragma once
// Shared by the config harnesses (fuzz_config: YAML text, read only; fuzz_config_tree: a config
// tree, read, built into a PLC that runs two scans). The only exception allowed out of the
// loader and the build is config::ConfigError, and its message starts with
// "<name>:<line>:<col>: " (docs/configuration.md, "Configuration"); anything else, or a crash,
// is a bug.

#include <spdlog/spdlog.h>

#include <cstdio>
#include <cstdlib>
#include <exception>
#include <memory>
#include <string>
#include <string_view>

#include "plcemu/config/config.hpp"
#include "plcemu/daemon/plc.hpp"

namespace plcemu::fuzz {

/// The file name the harnesses give their input; every error message starts with it.
inline constexpr std::string_view kConfigName = "fuzz.yaml";

/// Set by PLCEMU_FUZZ_VERBOSE=1: show what each input was refused for (seed debugging).
inline bool& config_verbose() {
    static bool v = false;
    return v;
}

/// For LLVMFuzzerInitialize: no log output, PLCEMU_FUZZ_VERBOSE read.
inline void init_config_harness() {
    spdlog::set_level(spdlog::level::off);
    config_verbose() = std::getenv("PLCEMU_FUZZ_VERBOSE") != nullptr;
}

[[noreturn]] inline void config_fail(const char* what, const char* detail) {
    std::fprintf(stderr, "invariant broken: %s: %s\n", what, detail);
    std::abort();
}

/// True for "<name>:<digits>:<digits>: ".
inline bool well_positioned(std::string_view m) {
    if (m.substr(0, kConfigName.size()) != kConfigName) return false;
    m.remove_prefix(kConfigName.size());
    for (int field = 0; field < 2; ++field) {
        if (m.empty() || m[0] != ':') return false;
        m.remove_prefix(1);
        std::size_t digits = 0;
        while (digits < m.size() && m[digits] >= '0' && m[digits] <= '9') ++digits;
        if (digits == 0) return false;
        m.remove_prefix(digits);
    }
    return m.substr(0, 2) == ": ";
}

/// Runs `body`, which reads a config: the only exception it may throw is a ConfigError whose
/// message starts with "<name>:<line>:<col>: ", as does each of the errors it carries (at most
/// config::Errors::kMax).
template <class Body>
void expect_config_errors_only(Body body) {
    try {
        body();
    } catch (const config::ConfigError& e) {
        if (!well_positioned(e.what())) config_fail("ConfigError without file:line:col", e.what());
        if (e.errors().size() > config::Errors::kMax) config_fail("too many errors", e.what());
        for (const auto& d : e.errors()) {
            const config::ConfigError one(d.pos, d.message);
            if (!well_positioned(one.what()))
                config_fail("ConfigError without file:line:col", one.what());
        }
        if (config_verbose()) {
            for (const auto& line : e.lines()) std::fprintf(stderr, "%s\n", line.c_str());
        }
    } catch (const std::exception& e) {
        config_fail("an exception other than ConfigError", e.what());
    } catch (...) {
        config_fail("an exception other than ConfigError", "not a std::exception");
    }
}

/// Reads a config with `read()` (which returns a config::Config), checking what comes out.
template <class Read>
void read_only(Read read) {
    expect_config_errors_only([&] { (void)read(); });
}

/// Reads a config with `read()` (which returns a config::Config), builds the PLC (binding the
/// program) and runs two scans, checking what comes out.
template <class Read>
void build_and_run(Read read) {
    expect_config_errors_only([&] {
        // Shared, not copied: the PLC keeps the config as a reload would.
        const auto c = std::make_shared<const config::Config>(read());
        daemon::Plc plc(c);
        plc.engine().run_scans(2);
    });
}

}  // namespace plcemu::fuzz
