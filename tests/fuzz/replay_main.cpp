// The fuzz harnesses without libFuzzer: each input named on the command line (a file, or every
// file of a directory, in name order) is given once to the harness's LLVMFuzzerTestOneInput.
// The unit tests build every harness with this file and the build's own compiler and sanitizers
// and replay its seeds and saved crash inputs (tests/CMakeLists.txt): a harness's invariants
// (config errors with their positions, the libmodbus oracle, a reset PLC equal to a new one)
// are checked on every corpus input in every test run, with no clang build. A broken invariant
// aborts, as under libFuzzer. scripts/fuzz.sh does the fuzzing.

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <system_error>
#include <vector>

// Defined by a harness, or not (libFuzzer's own driver treats it the same way).
extern "C" __attribute__((weak)) int LLVMFuzzerInitialize(int* argc, char*** argv);
extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size);

namespace {

namespace fs = std::filesystem;

bool run_file(const fs::path& path) {
    std::ifstream in(path, std::ios::binary);
    if (!in) {
        std::fprintf(stderr, "replay: cannot read %s\n", path.c_str());
        return false;
    }
    const std::vector<std::uint8_t> bytes{std::istreambuf_iterator<char>(in),
                                          std::istreambuf_iterator<char>()};
    LLVMFuzzerTestOneInput(bytes.data(), bytes.size());
    return true;
}

}  // namespace

int main(int argc, char** argv) {
    if (LLVMFuzzerInitialize != nullptr) LLVMFuzzerInitialize(&argc, &argv);
    std::size_t inputs = 0;
    for (int i = 1; i < argc; ++i) {
        const fs::path arg(argv[i]);
        std::error_code ec;
        if (!fs::is_directory(arg, ec)) {
            if (!run_file(arg)) return 1;
            ++inputs;
            continue;
        }
        std::vector<fs::path> files;
        for (const auto& entry : fs::directory_iterator(arg))
            if (entry.is_regular_file()) files.push_back(entry.path());
        std::sort(files.begin(), files.end());
        for (const auto& file : files) {
            if (!run_file(file)) return 1;
            ++inputs;
        }
    }
    // An empty corpus would make the test pass having checked nothing.
    if (inputs == 0) {
        std::fprintf(stderr, "replay: no input given\n");
        return 1;
    }
    std::printf("replay: %zu inputs, no invariant broken\n", inputs);
    return 0;
}
