// Scan-engine benchmarks (Google Benchmark): one scan of config/default.yaml with its ten loops
// running, one scan of 32 TPCTL points with their plant, and the virtual-time rate.

#include <benchmark/benchmark.h>

#include <chrono>
#include <string>

#include "plcemu/config/config.hpp"
#include "plcemu/daemon/plc.hpp"

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

}  // namespace

BENCHMARK_MAIN();
