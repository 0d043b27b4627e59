// The trends of the console's loops page (docs/console.md, "Loops"): one sample a simulated
// second of each loop's PV, SV and output, the last 10 simulated minutes, kept only once
// watched, started over for a new program.

#include "plcemu/engine/loop_history.hpp"

#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <memory>

#include "plcemu/image/image.hpp"
#include "support/profiles.hpp"

namespace plcemu::engine {
namespace {

using std::chrono::seconds;

image::Device r(std::uint32_t i) { return {image::Area::R, i, false}; }

// A loop over R0 (PV, 0.1 °C), R1 (SV) and R2 (output, full scale 200); with `pv` false it has
// no PV source until R9 is set (as a TPCTL's PV source appears once its modules have read).
class Looped final : public Instruction {
public:
    explicit Looped(bool pv)
        : pv_(pv) {}
    void execute(ScanContext& /*ctx*/) noexcept override {}
    void loops(const image::Image& image, Loops& out) const override {
        Loop l;
        l.name = pv_ ? "with pv" : "without pv";
        if (pv_ || image.read_word(r(9)) != 0) l.pv = r(0);
        l.sv = r(1);
        l.output = r(2);
        l.scale = 0.1;
        l.output_full = 200;
        out.push_back(l);
    }
    std::string_view mnemonic() const noexcept override { return "LOOPED"; }

private:
    bool pv_;
};

struct Rig {
    explicit Rig(bool pv = true) {
        Program p;
        p.push_back(std::make_unique<Looped>(pv));
        engine = std::make_unique<Engine>(img, EngineOptions{}, std::move(p));
        engine->power_up();
    }
    // Runs `n` scans of 10 ms, the history fed after each.
    void scans(int n, LoopHistory& h) {
        for (int i = 0; i < n; ++i) {
            engine->run_scans(1);
            h.after_scan(*engine);
        }
    }
    image::Image img{testing::fbs_layout()};
    std::unique_ptr<Engine> engine;
};

TEST(LoopHistory, KeepsNothingUntilWatched) {
    Rig rig;
    LoopHistory h;
    rig.scans(300, h);
    EXPECT_EQ(h.loops(), 0u);
    EXPECT_TRUE(h.samples(0).empty());
}

TEST(LoopHistory, SamplesEverySimulatedSecondInTheLoopsUnits) {
    Rig rig;
    LoopHistory h;
    h.watch();
    rig.img.write_word(r(0), 251);  // 25.1 °C
    rig.img.write_word(r(1), 1500);
    rig.img.write_word(r(2), 50);  // 25 % of 200
    rig.scans(1, h);
    rig.img.write_word(r(0), 0xFFF6);  // -1.0 °C: a signed word
    rig.scans(250, h);                 // 2.5 s more: samples at 1 s and 2 s
    ASSERT_EQ(h.loops(), 1u);
    const auto s = h.samples(0);
    ASSERT_EQ(s.size(), 3u);
    EXPECT_DOUBLE_EQ(s[1].t - s[0].t, 1.0);
    EXPECT_DOUBLE_EQ(s[2].t - s[1].t, 1.0);
    EXPECT_NEAR(s[0].pv, 25.1, 1e-9);
    EXPECT_NEAR(s[0].sv, 150.0, 1e-9);
    EXPECT_DOUBLE_EQ(s[0].output, 25.0);
    EXPECT_NEAR(s[2].pv, -1.0, 1e-9);
}

TEST(LoopHistory, KeepsTheLastTenSimulatedMinutes) {
    Rig rig;
    LoopHistory h;
    h.watch();
    rig.engine->run_scans(1);
    h.after_scan(*rig.engine);
    for (int second = 1; second <= 700; ++second) {
        rig.engine->run_scans(100);
        h.after_scan(*rig.engine);
    }
    const auto s = h.samples(0);
    ASSERT_EQ(s.size(), LoopHistory::kSamples);
    EXPECT_NEAR(s.back().t - s.front().t, 599.0, 1e-6);
    EXPECT_NEAR(s.back().t, std::chrono::duration<double>(rig.engine->now()).count(), 1e-6);
}

TEST(LoopHistory, ALoopWithoutPvSourceHasNaNUntilItHasOne) {
    Rig rig(false);
    LoopHistory h;
    h.watch();
    rig.img.write_word(r(0), 300);
    rig.scans(1, h);
    ASSERT_EQ(h.samples(0).size(), 1u);
    EXPECT_TRUE(std::isnan(h.samples(0)[0].pv));
    rig.img.write_word(r(9), 1);  // the source appears
    rig.scans(100, h);
    const auto s = h.samples(0);
    ASSERT_EQ(s.size(), 2u);  // the same loop: its history goes on
    EXPECT_NEAR(s[1].pv, 30.0, 1e-9);
}

TEST(LoopHistory, ANewEngineStartsItOver) {
    LoopHistory h;
    h.watch();
    {
        Rig first;
        first.scans(300, h);
        EXPECT_EQ(h.samples(0).size(), 3u);
    }
    Rig second(false);  // a reload: another engine, another program
    second.scans(1, h);
    const auto s = h.samples(0);
    ASSERT_EQ(s.size(), 1u);
    EXPECT_TRUE(std::isnan(s[0].pv));
}

}  // namespace
}  // namespace plcemu::engine
