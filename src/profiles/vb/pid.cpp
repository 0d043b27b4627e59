#include "profiles/vb/pid.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <optional>
#include <string>

#include "instructions/operands.hpp"
#include "profiles/vb/blocks.hpp"
#include "profiles/vb/operation_error.hpp"
#include "profiles/vb/relay_tuning.hpp"

namespace plcemu::profiles::vb {

namespace {

using image::Area;
using image::Range;
using instructions::BitSource;
using instructions::Operands;
using namespace pid;

constexpr double kMin16 = -32768.0;
constexpr double kMax16 = 32767.0;

/// The operands of one PID entry, checked.
struct Bound {
    BitSource en;
    std::uint32_t sv = 0;  // S1
    std::uint32_t pv = 0;  // S2
    std::uint32_t s3 = 0;  // first word of the parameter block
    std::uint32_t mv = 0;  // D
    int entry = 0;         // 1-based program position, for D9069
    bool step = false;     // whether `entry` is a listing's step number
    std::string ordinal;   // "program entry 5" or "step 5"
    std::string where;     // of the mnemonic
};

// A D register: the manual's operand table allows nothing else for S1, S2, S3 and D.
std::uint32_t d_register(Operands& ops, const char* key) {
    return ops.word_device(key, 1, {Area::D}).index;
}

Bound bind(const instructions::Entry& entry, const instructions::BindContext& ctx) {
    Operands ops(entry, ctx);
    Bound b;
    b.entry = entry.index;
    b.step = entry.step;
    b.ordinal = entry.ordinal();
    b.where = entry.where.text();
    b.en = ops.bit_source("en", true);
    b.sv = d_register(ops, "s1");
    b.pv = d_register(ops, "s2");
    b.s3 = d_register(ops, "s3");
    b.mv = d_register(ops, "d");
    ops.refuse_reserved("d", {Area::D, b.mv, 1});
    const Range block{Area::D, b.s3, kBlockWords};
    // Checked here rather than as 25 words of D: D9000–D9255 are D registers too, but not
    // ones a block may use.
    if (block.end() > kBlockAreaEnd) {
        ops.fail("s3", "S3 needs 25 registers in D0-D7999 (S3…S3+24), got " + ops.format(block));
    }
    ops.refuse_reserved("s3", block);
    // MV written into the block would overwrite a parameter every execution (D = S3 is the
    // sampling time).
    if (block.overlaps({Area::D, b.mv, 1})) {
        // Appended piece by piece: GCC 12's -Wrestrict takes `"D" + std::string&&` at -O2 for
        // an overlapping copy (a false positive that -Werror would make fatal).
        std::string why = ops.format({Area::D, b.mv, 1});
        why += " is S3+";
        why += std::to_string(b.mv - b.s3);
        why += ", in the PID's own block S3…S3+24 = ";
        why += ops.format(block);
        ops.fail("d", why);
    }
    // The block holds the loop's parameters and the instruction writes into it: two PIDs on one
    // block would overwrite each other's tuning results and alarms.
    for (const auto& c : ctx.earlier.claims) {
        if (block.overlaps(c.range)) {
            ops.fail("s3", "S3…S3+24 = " + ops.format(block) + " overlaps " + ops.format(c.range) +
                               ", owned by the " + std::string(c.mnemonic) + " at " + c.where);
        }
    }
    ops.finish();
    return b;
}

// A quantity held to 16 bits; NaN (which the law cannot produce from 16-bit inputs, but a
// clamp must not pass on) becomes 0.
double held16(double v) noexcept {
    if (std::isnan(v)) return 0.0;
    return std::clamp(v, kMin16, kMax16);
}

double milliseconds(engine::Duration d) noexcept {
    return std::chrono::duration<double, std::milli>(d).count();
}

/// S3+0…S3+6 and S3+14/15 as one execution reads them (signed 16-bit).
struct Params {
    int ts = 0;
    std::uint16_t control = 0;
    int alpha = 0;
    int kp = 0;
    int ti = 0;
    int kd = 0;
    int td = 0;

    bool on(std::uint16_t bit) const { return (control & bit) != 0; }
    /// The block is 25 words when b1, b2 or b5 is ON, else 20 (VB manual FNC88).
    bool long_block() const { return on(kPvAlarmOn) || on(kMvAlarmOn) || on(kMvLimitOn); }
};

// VB manual FNC88, error table: the parameter checks, in order; the first failing one stops
// the instruction. Kp, TI and TD are not checked while b4 asks for auto-tuning, which finds them.
std::optional<Code> check(const Params& p) {
    const bool tuning = p.on(kAutoTune);
    if (p.ts < 1) return kBadSampling;
    if (p.alpha < 0 || p.alpha > 99) return kBadFilter;
    if (!tuning && p.kp < 1) return kBadGain;
    if (!tuning && p.ti < 0) return kBadIntegral;
    if (p.kd < 0 || p.kd > 100) return kBadDerivGain;
    if (!tuning && p.td < 0) return kBadDerivative;
    return std::nullopt;
}

class Pid final : public engine::Instruction {
public:
    explicit Pid(Bound b)
        : b_(std::move(b)) {}

    void declare(engine::Declarations& out) const override {
        out.claims.push_back(
            {{Area::D, b_.s3, kBlockWords}, engine::ClaimKind::Working, "PID", b_.where});
    }

    // S3's words as docs/profile-vb.md, "FNC88 PID", lists them.
    void loops(const image::Image& /*image*/, engine::Loops& out) const override {
        auto d = [](std::uint32_t i) { return image::Device{Area::D, i, false}; };
        engine::Loop l;
        // The console's short name: "(entry 5)" in a YAML program, "(step 5)" in a listing.
        l.name = "PID D" + std::to_string(b_.pv) + (b_.step ? " (step " : " (entry ") +
                 std::to_string(b_.entry) + ")";
        l.pv = d(b_.pv);
        l.sv = d(b_.sv);
        l.output = d(b_.mv);
        l.output_full = 0;  // MV in the program's own units: shown as it is
        l.parameters = {{"Ts", d(b_.s3 + kSampling), "ms"},
                        {"Kp", d(b_.s3 + kGain), "%"},
                        {"TI", d(b_.s3 + kIntegral), "100 ms"},
                        {"TD", d(b_.s3 + kDerivative), "10 ms"}};
        l.alarms = {{"PV rose", d(b_.s3 + kAlarms), 0},
                    {"PV fell", d(b_.s3 + kAlarms), 1},
                    {"MV rose", d(b_.s3 + kAlarms), 2},
                    {"MV fell", d(b_.s3 + kAlarms), 3}};
        l.tuning = engine::LoopFlag{"auto-tuning", d(b_.s3 + kControl), 4};
        out.push_back(std::move(l));
    }

    void describe(const image::Image& /*image*/, engine::Tags& out) const override {
        struct Word {
            std::uint32_t offset;
            const char* what;
            engine::Number number;
        };
        using engine::Number;
        static constexpr Word kWords[] = {
            {kSampling, "sampling time Ts, ms", Number::Signed},
            {kControl,
             "control bits: b0 reverse (heating), b1 PV alarm, b2 MV alarm, b4 auto-tuning, b5 MV "
             "limit",
             Number::Unsigned},
            {kFilter, "input filter, %", Number::Signed},
            {kGain, "proportional gain Kp, %", Number::Signed},
            {kIntegral, "integral time TI, 100 ms", Number::Signed},
            {kDerivGain, "derivative filter KD, %", Number::Signed},
            {kDerivative, "derivative time TD, 10 ms", Number::Signed},
            {kTuneHigh, "auto-tuning output at 100 %", Number::Signed},
            {kTuneLow, "auto-tuning output at 0 %", Number::Signed},
            {kPvRiseAlarm, "PV change alarm (+)", Number::Signed},
            {kPvFallAlarm, "PV change alarm (-)", Number::Signed},
            {kMvUpper, "MV change alarm (+) with b2, MV upper limit with b5", Number::Signed},
            {kMvLower, "MV change alarm (-) with b2, MV lower limit with b5", Number::Signed},
            {kAlarms, "alarm bits: b0 PV rose, b1 PV fell, b2 MV rose, b3 MV fell",
             Number::Unsigned},
        };
        const std::string at = ", " + b_.ordinal + " (" + b_.where + ")";
        out.push_back({{Area::D, b_.sv, 1}, "PID S1 set value SV" + at});
        out.push_back({{Area::D, b_.pv, 1}, "PID S2 present value PV" + at});
        out.push_back({{Area::D, b_.mv, 1}, "PID D output MV" + at});
        for (std::uint32_t w = 0; w < kBlockWords; ++w) {
            std::string what = "working space (not written by the emulator)";
            Number number = Number::Unsigned;
            for (const auto& k : kWords) {
                if (k.offset != w) continue;
                what = k.what;
                number = k.number;
            }
            std::string text = "PID S3+" + std::to_string(w);
            text += ' ';
            text += what;
            out.push_back({{Area::D, b_.s3 + w, 1}, text + at, number});
        }
    }

    void execute(engine::ScanContext& ctx) noexcept override {
        // A power-up runs the program as loaded, whatever an earlier run of the engine left.
        if (ctx.first_scan) s_ = State{};
        image::Image& img = ctx.image;
        if (!b_.en.read(img)) {
            // EN OFF: D and S3+24 keep their values; an auto-tuning is abandoned with b4 left
            // ON, so it starts again at the next rise (VB manual FNC88, and docs).
            stop();
            return;
        }
        Params p = read(img);
        if (const auto code = check(p)) {
            fail(img, *code);
            return;
        }
        const bool first = !s_.running;
        // A rerun (EN OFF→ON, or a stopping error mended, after the loop has sampled) has the
        // loop's memory to compute with: it samples at once (VB manual FNC88: "rerun the PID
        // instruction for the instant response of output value (D)").
        // With b4 ON it starts the tuning instead, on the PV as it is now.
        const bool rerun = first && s_.sampled && !p.on(kAutoTune);
        if (first) first_execution(img, rerun);
        if (s_.tuning && !p.on(kAutoTune)) {
            // A master or the program cleared b4: the tuning is aborted and the PID goes on from
            // the current D with the parameters as they are.
            s_.tuning = false;
            s_.restart = true;
        }
        if (!s_.tuning && p.on(kAutoTune) && !start_tuning(ctx, p)) {
            // The tuning did not start and b4 is now OFF: the PID runs normally, so Kp, TI and
            // TD must pass the checks that b4 had skipped.
            p.control = static_cast<std::uint16_t>(p.control & ~kAutoTune);
            if (const auto code = check(p)) {
                fail(img, *code);
                return;
            }
        }
        if (rerun) {
            sample(ctx, p, rerun_sampling(ctx, p.ts));
            return;
        }
        // The very first execution has no memory to compute with: the first sampling comes Ts
        // later.
        if (first) return;
        if (const auto ts = sampling_due(ctx, p.ts)) sample(ctx, p, *ts);
    }

    std::string_view mnemonic() const noexcept override { return "PID"; }

private:
    /// The loop's memory between executions (the real PLC keeps it in S3+7…S3+19; the emulator
    /// keeps it here and writes nothing there).
    struct State {
        bool running = false;     // executed with EN ON since the last stop: not a first execution
        bool sampled = false;     // sampled since the power-up: a first execution is a rerun
        engine::Duration acc{0};  // sampling accumulator
        double pvnf1 = 0;         // PVnf−1
        double pvnf2 = 0;         // PVnf−2
        double ev1 = 0;           // EVn−1
        double dn1 = 0;           // Dn−1
        bool restart = true;      // the next sampling takes EVn−1 := EVn, Dn−1 := 0
        double mv = 0;            // MVn−1 as a real number
        std::uint16_t written = 0;  // what the instruction last stored in D
        bool tuning = false;
        int tune_hi = 0;  // S3+14/S3+15 as the tuning started
        int tune_lo = 0;
        RelayExperiment relay;
    };

    std::uint16_t word(const image::Image& img, std::uint32_t offset) const {
        return img.word(Area::D, b_.s3 + offset);
    }
    int signed_word(const image::Image& img, std::uint32_t offset) const {
        return static_cast<std::int16_t>(word(img, offset));
    }
    void set_word(image::Image& img, std::uint32_t offset, std::uint16_t v) const {
        img.set_word(Area::D, b_.s3 + offset, v);
    }
    int d(const image::Image& img, std::uint32_t reg) const {
        return static_cast<std::int16_t>(img.word(Area::D, reg));
    }

    Params read(const image::Image& img) const {
        Params p;
        p.ts = signed_word(img, kSampling);
        p.control = word(img, kControl);
        p.alpha = signed_word(img, kFilter);
        p.kp = signed_word(img, kGain);
        p.ti = signed_word(img, kIntegral);
        p.kd = signed_word(img, kDerivGain);
        p.td = signed_word(img, kDerivative);
        return p;
    }

    void raise(image::Image& img, std::uint16_t code) const {
        raise_operation_error(img, code, b_.entry);
    }

    // Stores MV in D and remembers it, so that a value someone else writes is recognised.
    void store(image::Image& img, double mv) {
        s_.mv = held16(mv);
        s_.written = static_cast<std::uint16_t>(static_cast<std::int16_t>(std::round(s_.mv)));
        img.set_word(Area::D, b_.mv, s_.written);
    }

    // Ends a run: the next execution with EN ON is a first execution.
    void stop() {
        s_.running = false;
        s_.tuning = false;
    }

    // A parameter error stops the PID: D, S3+24 and b4 are left as they are.
    void fail(image::Image& img, Code code) {
        raise(img, code);
        stop();
    }

    // VB manual FNC88, first execution: the accumulator at 0 and MVn−1 = D as it stands ("the
    // content value of D200 will be kept"). The very first one starts the PV history at the
    // current PV with Dn−1 = 0 and writes nothing; a rerun keeps the history (PVnf−1, PVnf−2,
    // EVn−1, Dn−1), which the real PLC holds in S3+7…S3+19 across EN OFF.
    void first_execution(const image::Image& img, bool rerun) {
        s_.running = true;
        s_.acc = engine::Duration{0};
        if (!rerun) {
            s_.pvnf1 = s_.pvnf2 = d(img, b_.pv);
            s_.dn1 = 0;
            s_.restart = true;
        }
        s_.written = img.word(Area::D, b_.mv);
        s_.mv = static_cast<std::int16_t>(s_.written);
    }

    // The Ts a rerun samples with: Ts, or the scan interval with 6740 when Ts is not above it
    // (as sampling_due); the accumulator stays at 0, so the next sampling comes Ts later.
    double rerun_sampling(engine::ScanContext& ctx, int ts_ms) const {
        if (ctx.dt > engine::Duration{0} && std::chrono::milliseconds(ts_ms) <= ctx.dt) {
            raise(ctx.image, kSamplingTooShort);
            return milliseconds(ctx.dt);
        }
        return static_cast<double>(ts_ms);
    }

    // The Ts to sample with when this execution samples. Ts ≤ the scan interval samples at
    // every scan with Ts taken as the scan interval and reports 6740 (VB manual FNC88: "the PLC
    // automatically sets sampling time = Scan Time"); otherwise the accumulator collects the
    // scan intervals and sampling keeps the remainder.
    std::optional<double> sampling_due(engine::ScanContext& ctx, int ts_ms) {
        // No simulated time passed: nothing to sample, and no zero Ts to divide by.
        if (ctx.dt <= engine::Duration{0}) return std::nullopt;
        const engine::Duration ts = std::chrono::milliseconds(ts_ms);
        if (ts <= ctx.dt) {
            raise(ctx.image, kSamplingTooShort);
            s_.acc = engine::Duration{0};
            return milliseconds(ctx.dt);
        }
        s_.acc += ctx.dt;
        if (s_.acc < ts) return std::nullopt;
        // One sampling per execution: a remainder of more than Ts (Ts was just made shorter)
        // keeps only its part below Ts, rather than sampling at every scan to catch up.
        s_.acc %= ts;
        return milliseconds(ts);
    }

    // The relay wants the high output while PV is on the side of SV that needs output.
    static bool demand(bool reverse, double pvnf, double sv) {
        return reverse ? pvnf < sv : pvnf > sv;
    }

    // VB manual FNC88, Auto-tuning Function, start: S3+14 must be above S3+15; the relay then
    // drives D at once.
    bool start_tuning(engine::ScanContext& ctx, const Params& p) {
        image::Image& img = ctx.image;
        const int hi = signed_word(img, kTuneHigh);
        const int lo = signed_word(img, kTuneLow);
        if (hi <= lo) {
            set_word(img, kControl, static_cast<std::uint16_t>(word(img, kControl) & ~kAutoTune));
            raise(img, kTuningFault);
            return false;
        }
        s_.tuning = true;
        s_.tune_hi = hi;
        s_.tune_lo = lo;
        s_.relay.start(ctx.now);
        s_.relay.observe(s_.pvnf1);
        s_.relay.decide(ctx.now, demand(p.on(kReverse), s_.pvnf1, d(img, b_.sv)));
        store(img, s_.relay.high() ? hi : lo);
        return true;
    }

    // One relay decision; at the third hi→lo change, the tuning's results. Returns the MV.
    double relay_step(engine::ScanContext& ctx, const Params& p, double pvnf, double sv) {
        image::Image& img = ctx.image;
        s_.relay.observe(pvnf);
        const auto state = s_.relay.decide(ctx.now, demand(p.on(kReverse), pvnf, sv));
        double mv = s_.relay.high() ? s_.tune_hi : s_.tune_lo;
        if (state != RelayExperiment::State::Measured) return mv;
        s_.tuning = false;
        s_.restart = true;
        set_word(img, kControl, static_cast<std::uint16_t>(word(img, kControl) & ~kAutoTune));
        const RelayCycle& c = s_.relay.cycle();
        if (!(c.a > 0) || !(c.tau > 0)) {
            // The PV did not swing (a frozen reading): no gains can be found.
            raise(img, kTuningFault);
            return mv;
        }
        const double span = s_.tune_hi - s_.tune_lo;
        const TunedGains g = ziegler_nichols(span, c);
        set_word(img, kGain, static_cast<std::uint16_t>(g.kp));
        set_word(img, kIntegral, static_cast<std::uint16_t>(g.ti));
        set_word(img, kDerivative, static_cast<std::uint16_t>(g.td));
        // The relay's mean output, so that the PID takes over without a bump.
        mv = std::round(s_.tune_lo + span * c.duty());
        return mv;
    }

    // A term of the law held to 16 bits; `code` when it had to be (the PID keeps operating).
    double checked(image::Image& img, double v, Code code) const {
        if (v >= kMin16 && v <= kMax16) return v;
        raise(img, code);
        return held16(v);
    }

    // VB manual FNC88, "The Equations of the PID Instruction" (velocity form): ΔMV from the
    // change of the error, the error, and the filtered second difference of PV.
    double law(image::Image& img,
               const Params& p,
               double ts,
               double ev,
               double dev,
               double pvnf,
               double& dn) const {
        const bool reverse = p.on(kReverse);
        dn = 0;
        if (p.td > 0) {
            const double td = 10.0 * p.td;            // ms
            const double kdtd = (p.kd / 100.0) * td;  // ms
            const double den = ts + kdtd;             // ≥ ts > 0
            const double second = pvnf - 2.0 * s_.pvnf1 + s_.pvnf2;
            dn = td / den * (reverse ? -second : second) + kdtd / den * s_.dn1;
        }
        const double k = p.kp / 100.0;
        const double prop = checked(img, k * dev, kProportionalOverflow);
        const double integ =
            p.ti > 0 ? checked(img, k * (ts / (100.0 * p.ti)) * ev, kIntegralOverflow) : 0.0;
        const double deriv = checked(img, k * dn, kDerivativeOverflow);
        return prop + integ + deriv;
    }

    // b5: MV held between S3+23 and S3+22 (swapped when given the wrong way round), before it is
    // stored, so the next ΔMV builds on the held value and nothing winds up. Without b5, MV is
    // held to 16 bits with 6747.
    double limit(image::Image& img, const Params& p, double mv) const {
        if (!p.on(kMvLimitOn)) return checked(img, mv, kMvOverflow);
        const int upper = signed_word(img, kMvUpper);
        const int lower = signed_word(img, kMvLower);
        return std::clamp(held16(mv), static_cast<double>(std::min(upper, lower)),
                          static_cast<double>(std::max(upper, lower)));
    }

    // VB manual FNC88, alarms: S3+24 re-evaluated at every sampling (25-word block only). The
    // MV change alarm is off while b5 uses S3+22/23 as limits.
    void alarms(image::Image& img, const Params& p, double dpv, int dmv) const {
        if (!p.long_block()) return;
        std::uint16_t flags = 0;
        if (p.on(kPvAlarmOn)) {
            if (dpv > signed_word(img, kPvRiseAlarm)) flags |= kPvRose;
            if (dpv < -static_cast<double>(signed_word(img, kPvFallAlarm))) flags |= kPvFell;
        }
        if (p.on(kMvAlarmOn) && !p.on(kMvLimitOn)) {
            if (dmv > signed_word(img, kMvUpper)) flags |= kMvRose;
            if (dmv < -signed_word(img, kMvLower)) flags |= kMvFell;
        }
        set_word(img, kAlarms, flags);
    }

    void sample(engine::ScanContext& ctx, const Params& p, double ts) {
        image::Image& img = ctx.image;
        const double alpha = p.alpha / 100.0;
        const double pvnf = alpha * s_.pvnf1 + (1.0 - alpha) * d(img, b_.pv);
        const double dpv = checked(img, pvnf - s_.pvnf1, kPvChangeOverflow);
        const double sv = d(img, b_.sv);
        const double ev = p.on(kReverse) ? sv - pvnf : pvnf - sv;
        if (s_.restart) {
            s_.ev1 = ev;
            s_.dn1 = 0;
            s_.restart = false;
        }
        const double dev = checked(img, ev - s_.ev1, kEvChangeOverflow);
        // Bumpless manual: a D that someone else wrote since the last sampling is MVn−1.
        const std::uint16_t now_d = img.word(Area::D, b_.mv);
        if (now_d != s_.written) s_.mv = static_cast<std::int16_t>(now_d);
        const int before = static_cast<std::int16_t>(now_d);
        double dn = 0;
        double mv = 0;
        if (s_.tuning) {
            mv = relay_step(ctx, p, pvnf, sv);
        } else {
            mv = limit(img, p, s_.mv + law(img, p, ts, ev, dev, pvnf, dn));
        }
        store(img, mv);
        alarms(img, p, dpv, static_cast<std::int16_t>(s_.written) - before);
        s_.pvnf2 = s_.pvnf1;
        s_.pvnf1 = pvnf;
        s_.ev1 = ev;
        s_.dn1 = dn;
        s_.sampled = true;
    }

    Bound b_;
    State s_;
};

}  // namespace

std::unique_ptr<engine::Instruction> make_pid(const instructions::Entry& entry,
                                              const instructions::BindContext& ctx) {
    return std::make_unique<Pid>(bind(entry, ctx));
}

}  // namespace plcemu::profiles::vb
