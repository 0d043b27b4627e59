#include "plcemu/engine/loop_history.hpp"

#include <algorithm>
#include <chrono>
#include <cstdint>
#include <limits>

namespace plcemu::engine {

namespace {

constexpr Duration kEvery = std::chrono::seconds(1);

double word(const image::Image& img, const image::Device& d) {
    return static_cast<std::int16_t>(img.read_word(d));
}

}  // namespace

Loops loops_of(const Engine& engine) {
    Loops found;
    for (const auto& instruction : engine.program()) instruction->loops(engine.image(), found);
    return found;
}

void LoopHistory::restart(const Engine& engine) {
    program_ = engine.program().data();
    loops_ = loops_of(engine);
    ring_.assign(kSamples * loops_.size(), LoopSample{});
    next_ = 0;
    rows_ = 0;
    due_ = engine.now();
}

void LoopHistory::after_scan(const Engine& engine) {
    if (!watched_) return;
    const Duration now = engine.now();
    // Another program, or an engine built anew (a reload: its scans count from 0 again, and
    // the new program may sit where the old one was), or simulated time gone back.
    if (engine.program().data() != program_ || engine.scans() < scans_ ||
        (rows_ > 0 && now + kEvery < due_)) {
        restart(engine);
    }
    scans_ = engine.scans();
    if (now < due_) return;
    due_ = now + kEvery;
    // Described again at each sample: where a PV comes from may depend on the image (a TPCTL's
    // PV source appears once its modules have read). Other loops (the program changed them)
    // start the history over.
    Loops described = loops_of(engine);
    const bool same = described.size() == loops_.size() &&
                      std::equal(described.begin(), described.end(), loops_.begin(),
                                 [](const Loop& a, const Loop& b) { return a.name == b.name; });
    if (!same) {
        restart(engine);
        due_ = now + kEvery;
    } else {
        loops_ = std::move(described);
    }
    if (loops_.empty()) return;
    const image::Image& img = engine.image();
    const double t = std::chrono::duration<double>(now).count();
    for (std::size_t i = 0; i < loops_.size(); ++i) {
        const Loop& l = loops_[i];
        LoopSample& s = ring_[next_ * loops_.size() + i];
        s.t = t;
        s.pv = l.pv ? word(img, *l.pv) * l.scale : std::numeric_limits<double>::quiet_NaN();
        s.sv = word(img, l.sv) * l.scale;
        s.output =
            l.output_full > 0 ? 100.0 * word(img, l.output) / l.output_full : word(img, l.output);
    }
    next_ = (next_ + 1) % kSamples;
    if (rows_ < kSamples) ++rows_;
}

std::vector<LoopSample> LoopHistory::samples(std::size_t i) const {
    std::vector<LoopSample> v;
    if (i >= loops_.size()) return v;
    v.reserve(rows_);
    for (std::size_t r = 0; r < rows_; ++r) {
        const std::size_t row = (next_ + kSamples - rows_ + r) % kSamples;
        v.push_back(ring_[row * loops_.size() + i]);
    }
    return v;
}

}  // namespace plcemu::engine
