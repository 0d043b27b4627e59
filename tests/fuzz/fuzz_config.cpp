// libFuzzer harness: the config loader from YAML text. Input: YAML text → config::parse_config
// → daemon::Plc (binding the program) → two scans, checked as config_support.hpp says. The
// YAML library's parse is most of an input's time here; fuzz_config_tree feeds the same loader
// trees without it.

#include <cstddef>
#include <cstdint>
#include <string>

#include "config_support.hpp"

using namespace plcemu;

extern "C" int LLVMFuzzerInitialize(int* /*argc*/, char*** /*argv*/) {
    fuzz::init_config_harness();
    return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    const std::string text(reinterpret_cast<const char*>(data), size);
    fuzz::build_and_run([&] { return config::parse_config(text, std::string(fuzz::kConfigName)); });
    return 0;
}
