// libFuzzer harness: a program written as an instruction list. Input: its first byte picks the
// profile (fbs, fb, vb: each with its own dialect), the rest is the listing's text, read line by
// line into a PLC's config and built (read_listing, then the rung checks and every operand's
// binding), then scanned. The only exception allowed is a ConfigError whose message starts with
// "fuzz.yaml:<line>:<col>: " on a line the input has; a program that builds must scan
// (docs/development.md, "Fuzzing").

#include <array>
#include <cstddef>
#include <cstdint>
#include <exception>
#include <string>
#include <string_view>

#include "config_support.hpp"
#include "plcemu/config/config.hpp"
#include "plcemu/daemon/plc.hpp"

using namespace plcemu;

namespace {

constexpr std::array<std::string_view, 3> kProfiles{"fbs", "fb", "vb"};

const config::Config& base(std::size_t profile) {
    static const std::array<config::Config, 3> configs = [] {
        std::array<config::Config, 3> c;
        for (std::size_t i = 0; i < c.size(); ++i) {
            c[i] = config::parse_config(
                "profile: " + std::string(kProfiles[i]) + "\npersistence: {enabled: false}\n",
                "fuzz.yaml");
        }
        return c;
    }();
    return configs[profile];
}

}  // namespace

extern "C" int LLVMFuzzerInitialize(int* /*argc*/, char*** /*argv*/) {
    fuzz::init_config_harness();
    return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    if (size == 0) return 0;
    config::Config c = base(data[0] % kProfiles.size());
    const std::string_view text(reinterpret_cast<const char*>(data) + 1, size - 1);
    int line = 1;
    std::size_t start = 0;
    while (start <= text.size()) {
        std::size_t end = text.find('\n', start);
        if (end == std::string_view::npos) end = text.size();
        c.listing.push_back({std::string(text.substr(start, end - start)),
                             {std::string(fuzz::kConfigName), line, 1}});
        if (end == text.size()) break;
        start = end + 1;
        ++line;
    }
    try {
        daemon::Plc plc(c);
        plc.engine().run_scans(3);
        (void)daemon::print_program(c);
    } catch (const config::ConfigError& e) {
        const auto& p = e.position();
        const std::string what = e.what();
        if (!fuzz::well_positioned(what) || p.line < 1 || p.line > line || p.column < 1) {
            fuzz::config_fail("a listing error at no position of the input", what.c_str());
        }
    } catch (const std::exception& e) {
        fuzz::config_fail("an exception other than ConfigError", e.what());
    }
    return 0;
}
