// Scan-engine benchmarks (Google Benchmark): one scan of config/default.yaml with its ten loops
// running, one scan of 32 TPCTL points with their plant, one scan of a 2,000-step instruction
// list beside a scan of an empty program (the reference), reading and building that list, and
// the virtual-time rate.

#include <benchmark/benchmark.h>

#include <chrono>
#include <string>

#include "plcemu/config/config.hpp"
#include "plcemu/daemon/plc.hpp"
#include "plcemu/profiles/profile.hpp"

namespace {

using plcemu::image::Area;

// Brings a PLC to steady running: loops enabled, measurement started, a few minutes simulated.
void warm_up(plcemu::daemon::Plc& plc, int points) {
    auto& img = plc.image();
    img.set_bit(Area::M, 0, true);
    for (int i = 0; i < points; ++i) img.set_bit(Area::M, 800u + static_cast<unsigned>(i), true);
    plc.engine().run_scans(30000);  // 5 simulated minutes at 10 ms
}

void run(benchmark::State& state, plcemu::daemon::Plc& plc) {
    auto& engine = plc.engine();
    for (auto _ : state) engine.run_scans(1);
    const double scan_s = std::chrono::duration<double>(engine.scan_period()).count();
    // Simulated seconds per wall second: how much faster than real time the engine can run.
    state.counters["sim_s_per_s"] = benchmark::Counter(
        scan_s * static_cast<double>(state.iterations()), benchmark::Counter::kIsRate);
}

void BM_ScanDefaultConfig(benchmark::State& state) {
    const auto cfg =
        plcemu::config::load_config(std::string(PLCEMU_SOURCE_DIR) + "/config/default.yaml");
    plcemu::daemon::Plc plc(cfg);
    warm_up(plc, 10);
    run(state, plc);
}
BENCHMARK(BM_ScanDefaultConfig);

// 32 points: two TC16 modules, one TPCTL over all of them, PWM on Y100-Y131 (Y10-Y25 are the
// modules' own outputs), WM800/WM816 enable.
const char* k32Points = R"(
profile: fbs
temperature:
  table: R5000
  modules: [TC16:K, TC16:K]
init:
  R5000: [0xA556, 2, 10000, 20000, 0x0103, 0x0103]
  R4005: 0
  R100: [1500, 1500, 1500, 1500, 1500, 1500, 1500, 1500, 1500, 1500, 1500, 1500, 1500, 1500, 1500, 1500,
         1500, 1500, 1500, 1500, 1500, 1500, 1500, 1500, 1500, 1500, 1500, 1500, 1500, 1500, 1500, 1500]
program:
  - MOV: {en: M1926, s: WM800, d: R4012}
  - MOV: {en: M1926, s: WM816, d: R4013}
  - TPCTL: {en: M0, hc: 1, md: 0, sn: 0, zn: 32, yn: Y100, sv: R100, os: R140, pr: R180,
            ir: R220, dr: R260, or: R300, wr: R400, err: M100, alm: M101}
)";

void BM_Scan32PointsWithPlant(benchmark::State& state) {
    const auto cfg = plcemu::config::parse_config(k32Points, "32-points.yaml");
    plcemu::daemon::Plc plc(cfg);
    warm_up(plc, 32);
    run(state, plc);
}
BENCHMARK(BM_Scan32PointsWithPlant);

// A 2,000-step program in WinProladder's mnemonic view (docs/program-language.md): 200 blocks of
// ten statements, each a rung of contacts with a block and an edge, a coil, a timer and a MOV.
std::string listing_2000() {
    std::string yaml = "profile: fbs\npersistence: {enabled: false}\nprogram:\n  il:\n";
    auto line = [&](const std::string& s) { yaml += "    - '" + s + "'\n"; };
    for (int i = 0; i < 200; ++i) {
        const std::string n = std::to_string(i);
        line("ORG X" + std::to_string(i % 32));
        line("AND NOT M" + n);
        line("LD M" + std::to_string(i + 1));
        line("OR TU X" + std::to_string((i + 1) % 32));
        line("ANDLD");
        line("OUT M" + std::to_string(1000 + i));
        line("ORG M" + std::to_string(1000 + i));
        line("TMR T" + n + " 100");
        line("ORG M1926");
        line("FUN8 MOV S:R" + n + " D:R" + std::to_string(1000 + i));
    }
    return yaml;
}

void BM_ScanListing2000Steps(benchmark::State& state) {
    const auto cfg = plcemu::config::parse_config(listing_2000(), "listing-2000.yaml");
    plcemu::daemon::Plc plc(cfg);
    if (plc.engine().program().size() != 2000) state.SkipWithError("not 2,000 steps");
    // Half the inputs ON, so both sides of every contact and block are taken.
    for (unsigned x = 0; x < 32; x += 2) plc.image().set_bit(Area::X, x, true);
    plc.engine().run_scans(100);
    run(state, plc);
}
BENCHMARK(BM_ScanListing2000Steps);

// What a start or a reload spends on that program: reading its 2,000 lines in the family's
// dialect (done twice for the fb and vb, whose config checks look for MBUS and TPSNS), and
// building it (the rung checks and every operand's binding, after one read).
void BM_ReadListing2000Lines(benchmark::State& state) {
    const auto cfg = plcemu::config::parse_config(listing_2000(), "listing-2000.yaml");
    for (auto _ : state) benchmark::DoNotOptimize(plcemu::profiles::listing_statements(cfg));
}
BENCHMARK(BM_ReadListing2000Lines)->Unit(benchmark::kMicrosecond);

void BM_BuildListing2000Steps(benchmark::State& state) {
    const auto cfg = plcemu::config::parse_config(listing_2000(), "listing-2000.yaml");
    for (auto _ : state) benchmark::DoNotOptimize(plcemu::daemon::build_program(cfg));
}
BENCHMARK(BM_BuildListing2000Steps)->Unit(benchmark::kMicrosecond);

// The reference: the same PLC with no program (specials and plant only).
void BM_ScanEmptyProgram(benchmark::State& state) {
    const auto cfg =
        plcemu::config::parse_config("profile: fbs\npersistence: {enabled: false}\n", "empty.yaml");
    plcemu::daemon::Plc plc(cfg);
    plc.engine().run_scans(100);
    run(state, plc);
}
BENCHMARK(BM_ScanEmptyProgram);

}  // namespace

BENCHMARK_MAIN();
