// libFuzzer harness: the config loader. Input: YAML text → config::parse_config → daemon::Plc
// (binding the program) → two scans. The only exception allowed out of the loader and the
// build is config::ConfigError, and its message starts with "<name>:<line>:<col>: "
// (docs/configuration.md, "Configuration"); anything else, or a crash, is a bug.

#include <spdlog/spdlog.h>

#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <memory>
#include <string>
#include <string_view>

#include "plcemu/config/config.hpp"
#include "plcemu/daemon/plc.hpp"

using namespace plcemu;

namespace {

constexpr std::string_view kName = "fuzz.yaml";
bool verbose = false;

[[noreturn]] void fail(const char* what, const char* detail) {
    std::fprintf(stderr, "invariant broken: %s: %s\n", what, detail);
    std::abort();
}

// "<name>:<digits>:<digits>: "
bool well_positioned(std::string_view m) {
    if (m.substr(0, kName.size()) != kName) return false;
    m.remove_prefix(kName.size());
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

}  // namespace

extern "C" int LLVMFuzzerInitialize(int* /*argc*/, char*** /*argv*/) {
    spdlog::set_level(spdlog::level::off);
    verbose = std::getenv("PLCEMU_FUZZ_VERBOSE") != nullptr;
    return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    const std::string text(reinterpret_cast<const char*>(data), size);
    try {
        // Shared, not copied: the PLC keeps the config as a reload would.
        const auto c =
            std::make_shared<const config::Config>(config::parse_config(text, std::string(kName)));
        daemon::Plc plc(c);
        plc.engine().run_scans(2);
    } catch (const config::ConfigError& e) {
        if (!well_positioned(e.what())) fail("ConfigError without file:line:col", e.what());
        // PLCEMU_FUZZ_VERBOSE=1 shows what each input was refused for (seed debugging).
        if (verbose) std::fprintf(stderr, "%s\n", e.what());
    } catch (const std::exception& e) {
        fail("an exception other than ConfigError", e.what());
    } catch (...) {
        fail("an exception other than ConfigError", "not a std::exception");
    }
    return 0;
}
