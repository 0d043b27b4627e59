// libFuzzer harness: the config loader's YAML front. Input: YAML text → config::parse_config
// (the YAML library's parse, the tree it becomes, every section read), checked as
// config_support.hpp says: syntax errors, aliases, nesting limits and the positions of errors.
// The YAML library's parse is most of an input's time here, so this harness stops at the
// config: fuzz_config_tree feeds the same loader trees without the YAML library, then builds
// the PLC and runs scans (docs/development.md, "Fuzzing").

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
    fuzz::read_only([&] { return config::parse_config(text, std::string(fuzz::kConfigName)); });
    return 0;
}
