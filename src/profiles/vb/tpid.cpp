#include "profiles/vb/tpid.hpp"

#include <algorithm>
#include <array>
#include <chrono>
#include <cstdint>
#include <limits>
#include <string>

#include "instructions/operands.hpp"
#include "profiles/vb/blocks.hpp"
#include "profiles/vb/operation_error.hpp"
#include "profiles/vb/tpid_loop.hpp"

namespace plcemu::profiles::vb {

namespace {

using image::Area;
using image::Range;
using instructions::BitSource;
using instructions::Operands;
using tpid::kFullScale;

constexpr int kMaxChannels = 16;
// S3: 10 system words, then 10 per channel; S4: 6 per channel.
constexpr std::uint32_t kS3Words = 10;
constexpr std::uint32_t kS4Words = 6;
// S3 words.
constexpr std::uint32_t kCycle = 0;
constexpr std::uint32_t kSensitivity = 1;
constexpr std::uint32_t kDirection = 2;
constexpr std::uint32_t kManual = 3;
constexpr std::uint32_t kTune = 4;
constexpr std::uint32_t kOutputs = 5;
constexpr std::uint32_t kLimitAlarms = 6;
constexpr std::uint32_t kDeviationAlarms = 7;
// S4 words, per channel.
constexpr std::uint32_t kKp = 0;
constexpr std::uint32_t kTi = 1;
constexpr std::uint32_t kTd = 2;
constexpr std::uint32_t kRepression = 3;
constexpr std::uint32_t kLimit = 4;
constexpr std::uint32_t kDeviation = 5;

// S3+0 counts 10 ms and may not be below 10 (100 ms).
constexpr int kMinCycle = 10;
constexpr auto kCycleUnit = std::chrono::milliseconds(10);
// The sensitivity levels 0 fast, 1 medium, 2 slow: Kp scaled down, TI up (docs/profile-vb.md).
constexpr std::array<double, 3> kGainFactor{1.0, 0.75, 0.5};
constexpr std::array<double, 3> kTimeFactor{1.0, 1.5, 2.0};

std::uint32_t s3_words(int n) { return kS3Words * static_cast<std::uint32_t>(n + 1); }
std::uint32_t s4_words(int n) { return kS4Words * static_cast<std::uint32_t>(n); }

struct Bound {
    BitSource en;
    std::uint32_t s1 = 0, s2 = 0, s3 = 0, s4 = 0;  // first D of each block
    bool n_constant = true;
    long long n = 0;        // the constant
    std::uint32_t n_d = 0;  // the D register otherwise
    int blocks_n = 1;       // the n the blocks were checked for (and are claimed for)
    std::string where;      // the entry's "file:line:col"
    int index = 0;          // the entry's 1-based position, for D9069
    std::string ordinal;    // "program entry 5" or "step 5"
};

Bound bind(const instructions::Entry& ic, const instructions::BindContext& ctx) {
    Operands ops(ic, ctx);
    Bound b;
    b.where = ic.where.text();
    b.index = ic.index;
    b.ordinal = ic.ordinal();
    b.en = ops.bit_source("en", true);
    // n: any integer is accepted, and a value outside 1–16 is an operation error at run time
    // (docs/profile-vb.md, "FNC92 TPID"); a register may hold up to 16 channels.
    if (ops.constant("n")) {
        b.n = ops.integer("n", -2147483648LL, 2147483647LL);
        b.blocks_n = static_cast<int>(std::clamp<long long>(b.n, 1, kMaxChannels));
    } else {
        b.n_constant = false;
        b.n_d = ops.word_device("n", 1, {Area::D}).index;
        b.blocks_n = kMaxChannels;
    }
    const auto n = static_cast<std::uint32_t>(b.blocks_n);
    b.s1 = d_block(ops, "s1", "S1 (SV)", n, Use::Read);
    b.s2 = d_block(ops, "s2", "S2 (PV)", n, Use::Read);
    b.s3 = d_block(ops, "s3", "S3", s3_words(b.blocks_n), Use::Written);
    b.s4 = d_block(ops, "s4", "S4", s4_words(b.blocks_n), Use::Written);
    ops.finish();

    // TPID writes S3 and (auto-tuning) S4: two instructions sharing them would fight, and S3
    // and S4 of one TPID may not share a word either.
    const Range s3{Area::D, b.s3, s3_words(b.blocks_n)};
    const Range s4{Area::D, b.s4, s4_words(b.blocks_n)};
    if (s3.overlaps(s4)) {
        ops.fail("s4", "S4 " + ops.format(s4) + " overlaps this TPID's S3 " + ops.format(s3));
    }
    for (const auto& c : ctx.earlier.claims) {
        const std::string of =
            ops.format(c.range) + " of the " + std::string(c.mnemonic) + " at " + c.where;
        if (s3.overlaps(c.range)) ops.fail("s3", "S3 " + ops.format(s3) + " overlaps " + of);
        if (s4.overlaps(c.range)) ops.fail("s4", "S4 " + ops.format(s4) + " overlaps " + of);
    }
    return b;
}

/// Values held to their ranges, remembering whether any was out of range (error 6705).
class Holder {
public:
    int within(int v, int lo, int hi) noexcept {
        if (v < lo || v > hi) faulty_ = true;
        return std::clamp(v, lo, hi);
    }
    int at_least(int v, int lo) noexcept { return within(v, lo, std::numeric_limits<int>::max()); }
    bool faulty() const noexcept { return faulty_; }

private:
    bool faulty_ = false;
};

class Tpid final : public engine::Instruction {
public:
    explicit Tpid(Bound b)
        : b_(std::move(b)) {}

    void declare(engine::Declarations& out) const override {
        out.claims.push_back({{Area::D, b_.s3, s3_words(b_.blocks_n)},
                              engine::ClaimKind::Working,
                              "TPID",
                              b_.where});
        out.claims.push_back({{Area::D, b_.s4, s4_words(b_.blocks_n)},
                              engine::ClaimKind::Working,
                              "TPID",
                              b_.where});
    }

    // S3 and S4 as docs/profile-vb.md, "FNC92 TPID", lists them, for the n the blocks were
    // checked for.
    void describe(const image::Image& /*image*/, engine::Tags& out) const override {
        using engine::Number;
        const std::string at = ", " + b_.ordinal + " (" + b_.where + ")";
        auto add = [&](std::uint32_t base, const char* block, std::uint32_t w,
                       const std::string& what, Number number) {
            std::string text = std::string("TPID ") + block + "+" + std::to_string(w);
            text += ' ';
            text += what;
            out.push_back({{Area::D, base + w, 1}, text + at, number});
        };
        const char* const kSystem[kS3Words] = {"control cycle Tc, 10 ms",
                                               "sensitivity: 0 fast, 1 medium, 2 slow",
                                               "direction bits (1 = forward), bit m channel m",
                                               "auto/manual bits (1 = manual)",
                                               "auto-tuning bits",
                                               "output bits (time-proportioned)",
                                               "limitation alarm bits",
                                               "deviation alarm bits",
                                               "system working area",
                                               "system working area"};
        for (std::uint32_t w = 0; w < kS3Words; ++w) {
            add(b_.s3, "S3", w, kSystem[w], w < kDirection ? Number::Signed : Number::Unsigned);
        }
        const char* const kGains[kS4Words] = {"Kp, 0.01",
                                              "TI, 100 ms",
                                              "TD, 10 ms",
                                              "overshoot repression R",
                                              "limitation alarm setting L",
                                              "deviation alarm setting Dv"};
        for (int m = 0; m < b_.blocks_n; ++m) {
            const std::string ch = "channel " + std::to_string(m) + " ";
            const auto mw = static_cast<std::uint32_t>(m);
            add(b_.s1, "S1", mw, ch + "set value SV", Number::Signed);
            add(b_.s2, "S2", mw, ch + "present value PV", Number::Signed);
            for (std::uint32_t w = 0; w < kS3Words; ++w) {
                add(b_.s3, "S3", kS3Words * (mw + 1) + w,
                    ch + (w == 0 ? "analog output, 0.1 %" : "working area"),
                    w == 0 ? Number::Signed : Number::Unsigned);
            }
            for (std::uint32_t w = 0; w < kS4Words; ++w)
                add(b_.s4, "S4", kS4Words * mw + w, ch + kGains[w], Number::Signed);
        }
    }

    void loops(const image::Image& image, engine::Loops& out) const override {
        auto d = [](std::uint32_t i) { return image::Device{Area::D, i, false}; };
        // The channels it runs: n, or what D(n) holds now (within the blocks checked for it).
        const long long n = b_.n_constant ? b_.n : i16(image, b_.n_d);
        const int channels = static_cast<int>(std::clamp<long long>(n, 0, b_.blocks_n));
        for (int m = 0; m < channels; ++m) {
            const auto mw = static_cast<std::uint32_t>(m);
            const auto bit = static_cast<std::uint8_t>(m);
            engine::Loop l;
            l.name = "TPID channel " + std::to_string(m) + " (D" + std::to_string(b_.s2 + mw) + ")";
            l.pv = d(b_.s2 + mw);
            l.sv = d(b_.s1 + mw);
            l.output = d(b_.s3 + kS3Words * (mw + 1));  // analog output, 0.1 %
            l.scale = 0.1;                              // the VB temperature modules' 0.1 °C
            l.unit = "°C";
            l.output_full = kFullScale;
            const std::uint32_t g = b_.s4 + kS4Words * mw;
            l.parameters = {{"Kp", d(g + kKp), "0.01"},
                            {"TI", d(g + kTi), "100 ms"},
                            {"TD", d(g + kTd), "10 ms"},
                            {"overshoot repression R", d(g + kRepression), ""},
                            {"limitation alarm L", d(g + kLimit), ""},
                            {"deviation alarm Dv", d(g + kDeviation), ""}};
            l.alarms = {{"limitation alarm", d(b_.s3 + kLimitAlarms), bit},
                        {"deviation alarm", d(b_.s3 + kDeviationAlarms), bit}};
            l.manual = engine::LoopFlag{"manual", d(b_.s3 + kManual), bit};
            l.tuning = engine::LoopFlag{"auto-tuning", d(b_.s3 + kTune), bit};
            out.push_back(std::move(l));
        }
    }

    void execute(engine::ScanContext& ctx) noexcept override {
        // A power-up runs the program as loaded, whatever an earlier run of the engine left.
        if (ctx.first_scan) s_ = State{};
        image::Image& img = ctx.image;
        if (!b_.en.read(img)) {
            stop(img);
            return;
        }
        const long long n = b_.n_constant ? b_.n : i16(img, b_.n_d);
        if (n < 1 || n > kMaxChannels) {
            // Not executed: the outputs keep their values, and the next valid execution starts
            // afresh as at EN rising.
            raise_operation_error(img, kOperandError, b_.index);
            const int written = s_.written_n;
            s_ = State{};
            s_.written_n = written;
            return;
        }
        run(ctx, static_cast<int>(n));
    }

    std::string_view mnemonic() const noexcept override { return "TPID"; }

private:
    struct State {
        bool running = false;            // executed at the previous scan (the cycle timer runs)
        int written_n = 0;               // channels whose outputs the last execution wrote
        engine::Duration cycle_start{};  // the current cycle's boundary
        engine::Duration cycle{};        // its length
        std::array<bool, kMaxChannels> started{};
        std::array<tpid::Loop, kMaxChannels> loops{};
    };

    static std::int16_t i16(const image::Image& img, std::uint32_t d) noexcept {
        return static_cast<std::int16_t>(img.word(Area::D, d));
    }
    std::int16_t s3(const image::Image& img, std::uint32_t w) const noexcept {
        return i16(img, b_.s3 + w);
    }
    std::uint32_t output_word(int c) const noexcept {
        return b_.s3 + kS3Words * static_cast<std::uint32_t>(c + 1);
    }

    // EN OFF: the outputs, the analog values and the alarms go to 0 once, and everything
    // starts again at the next rise (an AT bit still set restarts its experiment).
    void stop(image::Image& img) noexcept {
        if (s_.written_n > 0) {
            for (const std::uint32_t w : {kOutputs, kLimitAlarms, kDeviationAlarms}) {
                img.set_word(Area::D, b_.s3 + w, 0);
            }
            for (int c = 0; c < s_.written_n; ++c) img.set_word(Area::D, output_word(c), 0);
        }
        s_ = State{};
    }

    tpid::Settings settings(const image::Image& img, int c, int level, Holder& h) const noexcept {
        const std::uint32_t p = b_.s4 + kS4Words * static_cast<std::uint32_t>(c);
        const auto bit = [&](std::uint32_t w) { return ((s3(img, w) >> c) & 1) != 0; };
        tpid::Settings s;
        s.forward = bit(kDirection);
        s.manual = bit(kManual);
        s.tune = bit(kTune);
        const int kp = i16(img, p + kKp);
        // The manual's example I starts auto-tuning with the gains still 0.
        s.kp = s.tune ? std::max(kp, 1) : h.at_least(kp, 1);
        s.ti = h.at_least(i16(img, p + kTi), 0);
        s.td = h.at_least(i16(img, p + kTd), 0);
        s.r = h.at_least(i16(img, p + kRepression), 0);
        s.gain_factor = kGainFactor[static_cast<std::size_t>(level)];
        s.time_factor = kTimeFactor[static_cast<std::size_t>(level)];
        s.manual_value = std::clamp<int>(i16(img, output_word(c)), 0, kFullScale);
        return s;
    }

    void run(engine::ScanContext& ctx, int n) noexcept {
        image::Image& img = ctx.image;
        Holder h;
        const engine::Duration cycle = h.at_least(s3(img, kCycle), kMinCycle) * kCycleUnit;
        const int level = h.within(s3(img, kSensitivity), 0, 2);

        // Control-cycle boundaries at 0, Tc, 2Tc … from the start; a new Tc counts from the next.
        bool boundary = false;
        double ended_s = std::chrono::duration<double>(cycle).count();
        if (!s_.running) {
            s_.running = true;
            s_.cycle_start = ctx.now;
            boundary = true;
        } else if (ctx.now - s_.cycle_start >= s_.cycle) {
            boundary = true;
            ended_s = std::chrono::duration<double>(s_.cycle).count();
            s_.cycle_start += s_.cycle;
            // Scans further apart than a cycle: the cycle starts now rather than in the past.
            if (ctx.now - s_.cycle_start >= cycle) s_.cycle_start = ctx.now;
        }
        if (boundary) s_.cycle = cycle;
        const engine::Duration elapsed = ctx.now - s_.cycle_start;
        const double dt_s = std::chrono::duration<double>(ctx.dt).count();

        std::uint16_t outputs = 0, limit = 0, deviation = 0;
        std::uint16_t tune_bits = static_cast<std::uint16_t>(s3(img, kTune));
        for (int c = 0; c < kMaxChannels; ++c) {
            tpid::Loop& loop = s_.loops[static_cast<std::size_t>(c)];
            bool& started = s_.started[static_cast<std::size_t>(c)];
            if (c >= n) {
                // A channel n no longer covers starts afresh if n grows again.
                started = false;
                continue;
            }
            const tpid::Settings s = settings(img, c, level, h);
            const int sv = i16(img, b_.s1 + static_cast<std::uint32_t>(c));
            const int pv = i16(img, b_.s2 + static_cast<std::uint32_t>(c));
            if (!started) {
                loop.start(s);
                started = true;
            }
            loop.scan(s, sv, pv, dt_s);
            if (boundary) {
                const tpid::Cycle d = loop.boundary(s, sv, pv, ctx.now, ended_s);
                if (d.write_output) {
                    img.set_word(Area::D, output_word(c), static_cast<std::uint16_t>(d.output));
                }
                if (d.tuning != tpid::Tuning::None) {
                    tune_bits = static_cast<std::uint16_t>(tune_bits & ~(1u << c));
                    img.set_word(Area::D, b_.s3 + kTune, tune_bits);
                }
                if (d.tuning == tpid::Tuning::Done) {
                    const std::uint32_t p = b_.s4 + kS4Words * static_cast<std::uint32_t>(c);
                    img.set_word(Area::D, p + kKp, static_cast<std::uint16_t>(d.gains.kp));
                    img.set_word(Area::D, p + kTi, static_cast<std::uint16_t>(d.gains.ti));
                    img.set_word(Area::D, p + kTd, static_cast<std::uint16_t>(d.gains.td));
                } else if (d.tuning == tpid::Tuning::Failed) {
                    raise_operation_error(img, kTuningFault, b_.index);
                }
            }
            // The ON time is the latched output's share of the cycle, from its boundary.
            const bool on = elapsed.count() * kFullScale < loop.output() * s_.cycle.count();
            const std::int16_t l =
                i16(img, b_.s4 + kS4Words * static_cast<std::uint32_t>(c) + kLimit);
            const std::int16_t dv =
                i16(img, b_.s4 + kS4Words * static_cast<std::uint32_t>(c) + kDeviation);
            const auto mask = static_cast<std::uint16_t>(1u << c);
            if (on) outputs |= mask;
            if (s.forward ? pv < l : pv > l) limit |= mask;
            if (pv > sv + dv || pv < sv - dv) deviation |= mask;
        }
        img.set_word(Area::D, b_.s3 + kOutputs, outputs);
        img.set_word(Area::D, b_.s3 + kLimitAlarms, limit);
        img.set_word(Area::D, b_.s3 + kDeviationAlarms, deviation);
        s_.written_n = n;
        if (h.faulty()) raise_operation_error(img, kOperandError, b_.index);
    }

    Bound b_;
    State s_;
};

}  // namespace

std::unique_ptr<engine::Instruction> make_tpid(const instructions::Entry& ic,
                                               const instructions::BindContext& ctx) {
    return std::make_unique<Tpid>(bind(ic, ctx));
}

}  // namespace plcemu::profiles::vb
