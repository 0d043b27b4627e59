// libFuzzer harness: a program written as an instruction list. Input: its first byte picks the
// profile (fbs, fb, vb: each with its own dialect), the rest is the listing's text, read line by
// line into a PLC's config and built (read_listing, then the rung checks and every operand's
// binding), then scanned on an engine. The only exception allowed is a ConfigError whose message
// starts with "fuzz.yaml:<line>:<col>: " on a line the input has; a program that builds must scan
// (docs/development.md, "Fuzzing").

#include <array>
#include <cstddef>
#include <cstdint>
#include <exception>
#include <memory>
#include <string>
#include <string_view>

#include "config_support.hpp"
#include "plcemu/config/config.hpp"
#include "plcemu/daemon/plc.hpp"

using namespace plcemu;

namespace {

constexpr std::array<std::string_view, 3> kProfiles{"fbs", "fb", "vb"};

// Per profile: its config (read once) and an image the programs scan, kept between inputs.
// Building the program and scanning it on a bare engine, not a whole daemon::Plc (plant,
// specials, Modbus map), is what is fuzzed here and four times faster per input.
struct Rig {
    config::Config config;
    image::Image image;
};

Rig& rig(std::size_t profile) {
    static std::array<std::unique_ptr<Rig>, 3> rigs;
    if (!rigs[profile]) {
        auto c = config::parse_config(
            "profile: " + std::string(kProfiles[profile]) + "\npersistence: {enabled: false}\n",
            std::string(fuzz::kConfigName));
        const image::Layout layout = daemon::plc_layout(c);
        rigs[profile].reset(new Rig{std::move(c), image::Image(layout)});
    }
    return *rigs[profile];
}

}  // namespace

extern "C" int LLVMFuzzerInitialize(int* /*argc*/, char*** /*argv*/) {
    fuzz::init_config_harness();
    return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    if (size == 0) return 0;
    Rig& r = rig(data[0] % kProfiles.size());
    config::Config& c = r.config;
    c.listing.clear();
    r.image.clear();  // each input starts from a cleared image
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
        engine::Engine e(r.image, {}, daemon::build_program(c));
        e.run_scans(3);
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
    // The lines go with the input that made them: an input that leaves more allocations than
    // it frees is run again by libFuzzer under its leak checker (8 % of the time here).
    c.listing.clear();
    return 0;
}
