#include "profiles/fbs/tpctl.hpp"

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "instructions/operands.hpp"
#include "profiles/fatek/operands.hpp"
#include "profiles/fbs/services.hpp"
#include "profiles/fbs/special_registers.hpp"
#include "profiles/fbs/temperature_table.hpp"

namespace plcemu::profiles::fbs {

namespace {

using image::Area;
using image::Device;
using image::Range;
namespace sp = special;
using instructions::BindContext;
using instructions::BitSource;
using instructions::Operands;
using namespace tpctl;

// R4005 codes 0…5 → 1, 2, 4, 8, 16, 32 s.
constexpr int kMaxTimingCode = 5;

/// The operands of one TPCTL entry, checked.
struct Bound {
    BitSource en;
    BitSource hc;
    int md = 0;
    Device yn;
    long long sn = 0;
    long long zn = 0;
    bool valid = false;  // the Sn/Zn rule holds
    int points = 0;      // Zn when valid
    Device sv, os, pr, ir, dr, out, wr;
    std::optional<Device> err;
    std::optional<Device> alm;
    instructions::Where pos;  // of the mnemonic
};

bool sn_zn_valid(long long sn, long long zn) {
    return sn >= 0 && sn <= 31 && zn >= 1 && zn <= kMaxPoints && sn + zn <= kMaxPoints;
}

Bound bind(const instructions::Entry& ic, const BindContext& ctx) {
    Operands ops(ic, ctx);
    Bound b;
    b.pos = ic.where;
    b.en = ops.bit_source("en", true);
    b.hc = ops.bit_source("hc", true);
    b.md = ops.has("md") ? static_cast<int>(ops.integer("md", 0, 1)) : 0;
    // Sn/Zn: any integer is accepted here; out of the manual's range the instruction reports
    // ERR = 1 at run time (FBs manual §21.7) instead of refusing the program.
    b.sn = ops.integer("sn", -2147483648LL, 2147483647LL);
    b.zn = ops.integer("zn", -2147483648LL, 2147483647LL);
    b.valid = sn_zn_valid(b.sn, b.zn);
    b.points = b.valid ? static_cast<int>(b.zn) : 0;
    const auto span = static_cast<std::uint32_t>(std::max(b.points, 1));
    b.yn = ops.device("yn", span, {Area::Y});
    b.sv = fatek::register_block(ops, "sv", span);
    b.os = fatek::register_block(ops, "os", span);
    b.pr = fatek::register_block(ops, "pr", span);
    b.ir = fatek::register_block(ops, "ir", span);
    b.dr = fatek::register_block(ops, "dr", span);
    b.out = fatek::register_block(ops, "or", span);
    b.wr = fatek::register_block(ops, "wr", kWorkingWords);
    if (ops.has("err")) b.err = ops.bit_output("err");
    if (ops.has("alm")) b.alm = ops.bit_output("alm");
    ops.finish();
    return b;
}

Range block(const Device& d, int n) {
    return {d.area, d.index, static_cast<std::uint32_t>(std::max(n, 1))};
}

// The manual: "WR … can't be repeated in using". Two TPCTLs writing the same working registers,
// outputs or Y bits would fight each scan, and an operand inside the instruction's own WR would
// be overwritten, so both are refused at load.
void check_overlaps(const Bound& me, const instructions::Entry& ic, const BindContext& ctx) {
    if (!me.valid) return;
    Operands ops(ic, ctx);
    const Range wr = block(me.wr, kWorkingWords);
    const std::pair<const char*, Range> own[] = {
        {"sv", block(me.sv, me.points)}, {"os", block(me.os, me.points)},
        {"pr", block(me.pr, me.points)}, {"ir", block(me.ir, me.points)},
        {"dr", block(me.dr, me.points)}, {"or", block(me.out, me.points)}};
    for (const auto& [key, r] : own) {
        if (r.overlaps(wr)) {
            ops.fail(key, ops.format(r) + " overlaps this instruction's working registers " +
                              ops.format(wr));
        }
    }
    // Each pair is checked once, at the later entry, against what the earlier ones own.
    const Range mine_or = block(me.out, me.points);
    const Range mine_y = block(me.yn, me.points);
    for (const auto& c : ctx.earlier.claims) {
        const std::string of = " of the " + std::string(c.mnemonic) + " at " + c.where;
        switch (c.kind) {
            case engine::ClaimKind::Working:
                if (wr.overlaps(c.range)) {
                    ops.fail("wr", ops.format(wr) + " overlaps the working registers " +
                                       ops.format(c.range) + of + " (WR can't be repeated)");
                }
                if (mine_or.overlaps(c.range)) {
                    ops.fail("or", ops.format(mine_or) +
                                       " overlaps the outputs or working registers" + of);
                }
                break;
            case engine::ClaimKind::Output:
                if (mine_or.overlaps(c.range)) {
                    ops.fail("or", ops.format(mine_or) +
                                       " overlaps the outputs or working registers" + of);
                }
                if (wr.overlaps(c.range)) {
                    ops.fail("wr",
                             ops.format(wr) + " overlaps the outputs " + ops.format(c.range) + of);
                }
                break;
            case engine::ClaimKind::Pwm:
                if (mine_y.overlaps(c.range)) {
                    ops.fail("yn", ops.format(mine_y) + " overlaps the PWM outputs" + of);
                }
                break;
        }
    }
}

// A block of `span` words named in FATEK's register encoding (R4004, table SR+2/SR+3), when it
// lies in the image.
std::optional<Device> decode(const image::Image& img, std::uint16_t v, std::uint32_t span) {
    const std::optional<Device> d = temperature::decode_register(v);
    if (!d || !img.layout().contains({d->area, d->index, span})) return std::nullopt;
    return d;
}

std::chrono::seconds timing_code(unsigned code) {
    return std::chrono::seconds(1 << std::min<unsigned>(code, kMaxTimingCode));
}

/// One control point's state.
struct Point {
    double integral = 0.0;                       // Σ term, output counts
    int pv_prev = 0;                             // PV when the loop was last solved
    bool solved = false;                         // pv_prev is valid
    std::uint16_t output = 0;                    // OR value
    engine::Duration on{0};                      // PWM on-time latched for the current cycle
    int over_scans = 0;                          // consecutive scans with PV ≥ R4008
    bool over = false;                           // over-temperature warning
    std::optional<engine::Duration> high_since;  // output high while out of zone, since
    bool open = false;                           // heater-open warning

    void reset() { *this = Point{}; }
    /// Everything but the over-temperature count, which watches points without PID too.
    void reset_control() {
        const int n = over_scans;
        const bool o = over;
        reset();
        over_scans = n;
        over = o;
    }
};

class Tpctl final : public engine::Instruction {
public:
    Tpctl(Bound b, std::optional<Device> table)
        : b_(std::move(b)),
          table_(table) {}

    void declare(engine::Declarations& out) const override {
        if (!b_.valid) return;  // never executes, never writes
        const std::string at = b_.pos.text();
        out.claims.push_back(
            {block(b_.wr, kWorkingWords), engine::ClaimKind::Working, "TPCTL", at});
        out.claims.push_back({block(b_.out, b_.points), engine::ClaimKind::Output, "TPCTL", at});
        out.claims.push_back({block(b_.yn, b_.points), engine::ClaimKind::Pwm, "TPCTL", at});
        // Y(yn + i) switches the heater of temperature channel sn + i.
        for (int i = 0; i < b_.points; ++i) {
            Device y = b_.yn;
            y.index += static_cast<std::uint32_t>(i);
            out.actuators.push_back({static_cast<int>(b_.sn) + i, y});
        }
    }

    // The per-point blocks and WR as docs/profile-fbs.md, "FUN86 TPCTL", lists them.
    void describe(const image::Image& /*image*/, engine::Tags& out) const override {
        static const char* const kWords[kWorkingWords] = {
            "in-zone bits, points 0-15",
            "in-zone bits, points 16-31",
            "warning bits, points 0-15",
            "warning bits, points 16-31",
            "PWM cycle (high byte) and solution interval (low byte), s",
            "over-temperature bits, points 0-15",
            "over-temperature bits, points 16-31",
            "heater-open bits, points 0-15",
            "heater-open bits, points 16-31"};
        const std::string at = ", TPCTL at " + b_.pos.text();
        // Point i of each per-point block, on temperature channel Sn+i.
        const std::pair<const Device*, const char*> points[] = {
            {&b_.sv, "setpoint, 0.1 degree"}, {&b_.os, "in-zone offset, 0.1 degree"},
            {&b_.pr, "Kc, 1-9999"},           {&b_.ir, "Ki, 0.01 repeats/min"},
            {&b_.dr, "Td, 0.01 min"},         {&b_.out, "PID output, 0-16383"}};
        for (int i = 0; i < b_.points; ++i) {
            const std::string point = "TPCTL point " + std::to_string(i) + " (channel " +
                                      std::to_string(b_.sn + i) + ") ";
            for (const auto& [block, what] : points) {
                out.push_back({{block->area, block->index + static_cast<std::uint32_t>(i), 1},
                               (point + what).append(at)});
            }
            out.push_back({{b_.yn.area, b_.yn.index + static_cast<std::uint32_t>(i), 1},
                           (point + "PWM output").append(at)});
        }
        for (std::uint32_t w = 0; w < kWorkingWords; ++w) {
            Device d = b_.wr;
            d.index += w;
            out.push_back({{d.area, d.index, 1},
                           "TPCTL WR+" + std::to_string(w) + " " + kWords[w] + at,
                           engine::Number::Unsigned});
        }
    }

    void execute(engine::ScanContext& ctx) noexcept override {
        // The first scan after a power-up runs the program as loaded (docs/profile-fbs.md,
        // "FUN86 TPCTL": first execution), whatever an earlier run of the engine left here.
        if (ctx.first_scan) *this = Tpctl(std::move(b_), table_);
        image::Image& img = ctx.image;
        const bool en = b_.en.read(img);
        const bool rising = en && !prev_en_;
        prev_en_ = en;
        if (!b_.valid) {
            // Sn/Zn out of range: not executed, ERR on (FBs manual §21.7).
            write_bit(img, b_.err, true);
            write_bit(img, b_.alm, false);
            return;
        }
        write_bit(img, b_.err, false);
        if (rising) {
            // R4005 is read only here: changes while EN = 1 wait for the next rise (manual note 1).
            const std::uint16_t t = img.word(Area::R, sp::kPidTiming);
            ts_ = timing_code(t & 0xFFu);
            pwm_ = timing_code(static_cast<unsigned>(t >> 8));
        }
        if (!en) {
            stop(img);
            return;
        }
        if (!defaults_given_) {
            first_execution(img);
            defaults_given_ = true;
        }
        const std::optional<Device> pv_start = pv_source(img);
        if (!pv_start) {
            // "FUN86 will be enabled after reading all temperature channels."
            stop(img);
            return;
        }
        run(ctx, *pv_start);
    }

    std::string_view mnemonic() const noexcept override { return "TPCTL"; }

private:
    static void write_bit(image::Image& img, const std::optional<Device>& d, bool v) {
        if (d) img.write_bit(*d, v);
    }

    std::uint16_t word(const image::Image& img, const Device& base, int i) const {
        return img.word(base.area, base.index + static_cast<std::uint32_t>(i));
    }
    void set_word(image::Image& img, const Device& base, int i, std::uint16_t v) const {
        img.set_word(base.area, base.index + static_cast<std::uint32_t>(i), v);
    }
    void set_y(image::Image& img, int i, bool v) const {
        img.set_bit(Area::Y, b_.yn.index + static_cast<std::uint32_t>(i), v);
    }

    // The manual's "when performing the instruction the first time": default gains for every
    // point whose PR is still 0 (a retained, tuned PR is kept).
    void first_execution(image::Image& img) const {
        for (int i = 0; i < b_.points; ++i) {
            if (word(img, b_.pr, i) != 0) continue;
            set_word(img, b_.pr, i, kDefaultKc);
            set_word(img, b_.ir, i, kDefaultKi);
            set_word(img, b_.dr, i, kDefaultTd);
        }
    }

    // Where the readings are, or nothing while the measurement is not running. R4003 = A55Ah
    // takes the PVs from R4004's block, which the program fills itself, so the module's execute
    // code does not gate it.
    std::optional<Device> pv_source(const image::Image& img) const {
        const auto needed = static_cast<std::uint32_t>(b_.sn + b_.zn);
        if (img.word(Area::R, sp::kTempMeasureRemap) == kPvRemap) {
            return decode(img, img.word(Area::R, sp::kTempPvSource), needed);
        }
        if (!table_ || !img.layout().contains({table_->area, table_->index, 4})) {
            return std::nullopt;
        }
        const std::uint16_t* t = img.words(table_->area) + table_->index;
        if (t[0] != temperature::kValidTable) return std::nullopt;
        const std::optional<Device> wr = decode(img, t[3], 1);
        if (!wr || (img.word(wr->area, wr->index) >> 8) != kMeasurementRunning) {
            return std::nullopt;
        }
        return decode(img, t[2], needed);
    }

    // EN = 0 (or no measurement): Y off, OR 0, PID state reset, status cleared.
    void stop(image::Image& img) {
        for (int i = 0; i < b_.points; ++i) {
            set_y(img, i, false);
            set_word(img, b_.out, i, 0);
            points_[static_cast<std::size_t>(i)].reset();
        }
        for (std::uint32_t w = 0; w < kWorkingWords; ++w)
            img.set_word(b_.wr.area, b_.wr.index + w, 0);
        write_bit(img, b_.alm, false);
        running_ = false;
    }

    bool pid_enabled(const image::Image& img, int channel) const {
        const std::uint16_t w =
            img.word(Area::R, sp::kPidEnable + static_cast<std::uint32_t>(channel / 16));
        return ((w >> (channel % 16)) & 1u) != 0;
    }

    void run(engine::ScanContext& ctx, const Device& pv_start) {
        image::Image& img = ctx.image;
        const bool heating = b_.hc.read(img);
        if (!running_ || heating != heating_) {
            // Start (or a change of action): solve now, start a PWM cycle now, from fresh state.
            for (auto& p : points_) p.reset();
            running_ = true;
            heating_ = heating;
            next_solve_ = ctx.now;
            cycle_start_ = ctx.now;
            cycle_due_ = true;
        }
        bool solve = false;
        if (ctx.now >= next_solve_) {
            solve = true;
            next_solve_ += ts_;
            if (next_solve_ <= ctx.now) next_solve_ = ctx.now + ts_;  // after a jump in time
        }
        if (ctx.now >= cycle_start_ + pwm_) {
            cycle_start_ += pwm_;
            if (cycle_start_ + pwm_ <= ctx.now) cycle_start_ = ctx.now;
            cycle_due_ = true;
        }
        const bool new_cycle = cycle_due_;
        cycle_due_ = false;

        const int over_limit = std::max<int>(img.word(Area::R, sp::kOverTemperature), 100);
        const int open_percent =
            std::clamp<int>(img.word(Area::R, sp::kHeaterOpenPercent), 80, 100);
        const auto open_time =
            std::chrono::seconds(std::max<int>(img.word(Area::R, sp::kHeaterOpenSeconds), 60));

        std::uint32_t in_zone = 0, warn = 0, over_bits = 0, open_bits = 0;
        bool alarm = false;
        for (int i = 0; i < b_.points; ++i) {
            Point& p = points_[static_cast<std::size_t>(i)];
            const int channel = static_cast<int>(b_.sn) + i;
            const std::uint16_t raw =
                img.word(pv_start.area, pv_start.index + static_cast<std::uint32_t>(channel));
            const bool broken = raw == kBrokenReading;
            const bool enabled = pid_enabled(img, channel);
            const int pv = static_cast<std::int16_t>(raw);
            const int sv = static_cast<std::int16_t>(word(img, b_.sv, i));
            const int os = word(img, b_.os, i);

            // Over-temperature guards against a shorted SSR, which does not care whether the
            // point runs PID: every point with a temperature is watched.
            p.over_scans =
                !broken && pv >= over_limit ? std::min(p.over_scans + 1, kOverTemperatureScans) : 0;
            p.over = p.over_scans >= kOverTemperatureScans;

            bool zone = false;
            if (!enabled || broken) {
                // R4012/R4013 bit 0: no PID, output off. A broken sensor: no PV to control on,
                // so the output is off too, and the point is out of zone (ALM).
                p.reset_control();
                set_y(img, i, false);
                set_word(img, b_.out, i, 0);
                if (enabled) alarm = true;
            } else {
                if (solve) solve_point(img, i, p, pv, sv);
                set_word(img, b_.out, i, p.output);
                if (new_cycle) {
                    p.on =
                        std::chrono::duration_cast<engine::Duration>(pwm_ * p.output) / kFullScale;
                }
                // ON for OR/16383 of the cycle, to the nearest scan: a scan holds its Y for dt.
                set_y(img, i, (ctx.now - cycle_start_) + ctx.dt / 2 < p.on);

                zone = pv >= sv - os && pv <= sv + os;
                if (!zone && p.output * 100 >= open_percent * kFullScale) {
                    if (!p.high_since) p.high_since = ctx.now;
                    p.open = ctx.now - *p.high_since >= open_time;
                } else {
                    p.high_since.reset();
                    p.open = false;
                }
                alarm = alarm || !zone;
            }
            const std::uint32_t bit = 1u << i;
            if (zone) in_zone |= bit;
            if (p.over) over_bits |= bit;
            if (p.open) open_bits |= bit;
            if (p.over || p.open) warn |= bit;
            alarm = alarm || p.over || p.open;
        }
        set_word(img, b_.wr, 0, static_cast<std::uint16_t>(in_zone & 0xFFFF));
        set_word(img, b_.wr, 1, static_cast<std::uint16_t>(in_zone >> 16));
        set_word(img, b_.wr, 2, static_cast<std::uint16_t>(warn & 0xFFFF));
        set_word(img, b_.wr, 3, static_cast<std::uint16_t>(warn >> 16));
        // WR+4…WR+8, "used by this instruction": the state lives here in the instruction; these
        // words only show it (timing in effect, and the cause behind each warning bit).
        set_word(img, b_.wr, 4, static_cast<std::uint16_t>((pwm_.count() << 8) | ts_.count()));
        set_word(img, b_.wr, 5, static_cast<std::uint16_t>(over_bits & 0xFFFF));
        set_word(img, b_.wr, 6, static_cast<std::uint16_t>(over_bits >> 16));
        set_word(img, b_.wr, 7, static_cast<std::uint16_t>(open_bits & 0xFFFF));
        set_word(img, b_.wr, 8, static_cast<std::uint16_t>(open_bits >> 16));
        write_bit(img, b_.alm, alarm);
    }

    // The positional PID of FBs manual §21.7 (docs/profile-fbs.md, "FUN86 TPCTL"), E in 0.1°,
    // output in counts of 0–16383.
    void solve_point(const image::Image& img, int i, Point& p, int pv, int sv) const {
        const double kc = std::clamp<int>(word(img, b_.pr, i), 1, 9999);
        const double ki = std::min<int>(word(img, b_.ir, i), 9999);
        const double td = std::min<int>(word(img, b_.dr, i), 9999);
        const double ts = static_cast<double>(ts_.count());
        const double e = heating_ ? sv - pv : pv - sv;
        const double prop = kc * e;  // reaches 16383 at the proportional band (Kc 110 → 14.9°)
        double deriv = 0.0;
        if (p.solved) {
            // Against the change of PV, in the direction that reduces the error.
            const double towards = heating_ ? pv - p.pv_prev : p.pv_prev - pv;
            deriv = -kc * (td / 100.0 * 60.0) * towards / ts;
        }
        p.pv_prev = pv;
        p.solved = true;
        // Md 0 (modified minimum overshoot): integrate only inside the proportional band.
        if (b_.md == 1 || std::abs(prop) < kFullScale) {
            const double step = kc * (ki / 100.0) * (ts / 60.0) * e;
            double next = p.integral + step;
            // No wind-up: integrating never pushes the output further past 0 or full scale.
            if (step > 0) next = std::min(next, std::max(p.integral, kFullScale - prop - deriv));
            if (step < 0) next = std::max(next, std::min(p.integral, -prop - deriv));
            p.integral = std::clamp(next, 0.0, static_cast<double>(kFullScale));
        }
        const double m =
            std::clamp(prop + p.integral + deriv, 0.0, static_cast<double>(kFullScale));
        p.output = static_cast<std::uint16_t>(std::lround(m));
    }

    Bound b_;
    std::optional<Device> table_;
    std::array<Point, kMaxPoints> points_{};
    bool prev_en_ = false;
    bool defaults_given_ = false;
    bool running_ = false;
    bool heating_ = true;
    bool cycle_due_ = false;
    std::chrono::seconds ts_{4};
    std::chrono::seconds pwm_{2};
    engine::Duration next_solve_{0};
    engine::Duration cycle_start_{0};
};

}  // namespace

std::unique_ptr<engine::Instruction> make_tpctl(const instructions::Entry& ic,
                                                const BindContext& ctx) {
    Bound b = bind(ic, ctx);
    Operands ops(ic, ctx);
    ops.refuse_reserved("yn", block(b.yn, b.points));
    if (b.err) ops.refuse_reserved("err", block(*b.err, 1));
    if (b.alm) ops.refuse_reserved("alm", block(*b.alm, 1));
    check_overlaps(b, ic, ctx);
    const auto* fs = dynamic_cast<const Services*>(&ctx.services);
    return std::make_unique<Tpctl>(std::move(b),
                                   fs ? fs->temperature_table : std::optional<Device>{});
}

}  // namespace plcemu::profiles::fbs
