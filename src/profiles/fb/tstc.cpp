#include "profiles/fb/tstc.hpp"

#include <array>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "instructions/operands.hpp"
#include "profiles/fatek/operands.hpp"
#include "profiles/fatek/temperature_loop.hpp"
#include "profiles/fb/conversion.hpp"
#include "profiles/fb/module_cycle.hpp"
#include "profiles/fb/services.hpp"
#include "profiles/fb/special_registers.hpp"

namespace plcemu::profiles::fb {

namespace tstc {

std::uint16_t default_kc(int sensor, int pl) {
    // FB manual FUN73: "0~10V … 60", "0~5V … 30", "-10~10V … 120", "-5~5V … 60". The RTD
    // modules are bipolar: 120 on a 10 V span, 60 on a 5 V one.
    static constexpr std::array<std::uint16_t, 4> kThermocouple{60, 30, 120, 60};
    if (thermocouple(sensor)) return kThermocouple[static_cast<std::size_t>(pl)];
    return pl == 0 || pl == 2 ? 120 : 60;
}

double full_scale(int sensor, int pl, bool fahrenheit, bool jis) {
    // Pb = 100 % / Kc of the converter's full scale: 1000/500/2000/1000 °C for thermocouples,
    // the measuring range in 0.1 °C for RTDs (docs/profile-fb.md, "FUN73 TSTC").
    static constexpr std::array<double, 4> kThermocouple{1000.0, 500.0, 2000.0, 1000.0};
    double fs = 0.0;
    if (thermocouple(sensor)) {
        fs = kThermocouple[static_cast<std::size_t>(pl)];
    } else {
        const RtdRange r = rtd_range(sensor, pl, jis);
        fs = (r.hi - r.lo) * 10.0;
    }
    return fahrenheit ? fs * 1.8 : fs;
}

}  // namespace tstc

namespace {

using image::Area;
using image::Device;
using instructions::BitSource;
using instructions::Operands;
using namespace tstc;

// The FB's figures for the FATEK loop (FB manual FUN73): OR 0–4095, Kc/Ti/Td up to 999, R4007
// from 300 s, R4008 whole degrees from 50, R4005 codes 0 → 2 s, 1 → 4 s, 2 → 8 s, ≥ 3 → 1 s; a
// broken point's reading is a temperature that counts for over-temperature; Os < 0 is never in
// zone.
const fatek::LoopRules kRules{kFullScale, kGainCeiling, 300, 50, {2, 4, 8, 1}, true, true};

struct Bound {
    BitSource en;
    BitSource hc;
    ModuleOperands m;
    long long sh = 0;
    long long zh = 0;
    bool valid = false;  // Tp, Pl, Sm, Sh and Zh in range: the instruction runs
    int points = 0;      // Zh when valid
    Device yh;
    fatek::LoopBlocks l;  // sv, os, pr, ir, dr, or
    std::optional<Device> err, ao0, ao1;
    std::string where;
};

Bound bind(const instructions::Entry& ic, const instructions::BindContext& ctx) {
    constexpr long long kAny = 2147483647LL;
    Operands ops(ic, ctx);
    Bound b;
    b.where = ic.where.text();
    b.en = ops.bit_source("en", true);
    b.hc = ops.bit_source("hc", true);
    b.m = bind_module(ops, kWorkingWords);
    // Sh/Zh: any integer here; out of range the instruction reports ERR at run time (FB manual
    // FUN73: "Sh or Zh out of range, or Sh < Sm").
    b.sh = ops.integer("sh", -kAny, kAny);
    b.zh = ops.integer("zh", -kAny, kAny);
    b.valid = b.m.valid && b.sh >= b.m.sm && b.sh <= 31 && b.zh >= 1 && b.sh + b.zh <= 32;
    b.points = b.valid ? static_cast<int>(b.zh) : 0;
    const auto span = static_cast<std::uint32_t>(b.points > 0 ? b.points : 1);
    b.yh = ops.device("yh", span, {Area::Y});
    fatek::bind_point_blocks(ops, span, b.l);
    if (ops.has("err")) b.err = ops.bit_output("err");
    if (ops.has("ao0")) b.ao0 = ops.bit_output("ao0");
    if (ops.has("ao1")) b.ao1 = ops.bit_output("ao1");
    ops.finish();
    ops.refuse_reserved("yh", {Area::Y, b.yh.index, span});
    const std::pair<const char*, const std::optional<Device>*> bits[] = {
        {"err", &b.err}, {"ao0", &b.ao0}, {"ao1", &b.ao1}};
    for (const auto& [key, d] : bits) {
        if (*d) ops.refuse_reserved(key, {(*d)->area, (*d)->index, 1});
    }
    return b;
}

fatek::LoopBlocks loop_blocks(const Bound& b) {
    Device status = b.m.wr;
    status.index += kLoopWords;
    fatek::LoopBlocks l = b.l;
    l.y = b.yh;
    l.status = status;
    l.first = static_cast<int>(b.sh);
    l.points = b.points;
    return l;
}

class Tstc final : public engine::Instruction {
public:
    Tstc(Bound b, std::shared_ptr<Points> points, std::vector<engine::Claim> claims)
        : b_(std::move(b)),
          points_(points),
          claims_(std::move(claims)),
          cycle_(b_.m, std::move(points)),
          loop_(&kRules, loop_blocks(b_), 1.0, false, 1) {}

    void declare(engine::Declarations& out) const override {
        for (const auto& c : claims_) out.claims.push_back(c);
        // Y(yh + i) switches the heater of temperature channel sh + i.
        for (int i = 0; i < b_.points; ++i) {
            Device y = b_.yh;
            y.index += static_cast<std::uint32_t>(i);
            out.actuators.push_back({static_cast<int>(b_.sh) + i, y});
        }
    }

    void execute(engine::ScanContext& ctx) noexcept override {
        image::Image& img = ctx.image;
        if (ctx.first_scan) {
            cycle_.reset();
            loop_ = fatek::TemperatureLoop(&kRules, loop_blocks(b_), 1.0, false, 1);
            prev_en_ = false;
        }
        if (!b_.valid) {
            // Tp, Pl, Sm, Sh or Zh out of range: not executed, ERR ON (FB manual FUN73).
            write_bit(img, b_.err, true);
            return;
        }
        write_bit(img, b_.err, false);
        const bool en = b_.en.read(img);
        const bool rising = en && !prev_en_;
        prev_en_ = en;
        cycle_.run(ctx, en);
        write_bit(img, b_.ao0, cycle_.broken_bits() != 0);
        // R4005 is read when EN rises: a change while EN = 1 waits for the next (note 1).
        if (rising) loop_.latch_timing(img);
        if (!en) {
            stop(img);
            return;
        }
        // "At the first execution the system gives every point the default Kc, Ti and Td":
        // the points whose PR is still 0.
        const int tp = static_cast<int>(b_.m.tp);
        const int pl = static_cast<int>(b_.m.pl);
        loop_.first_execution(img, {default_kc(tp, pl), kDefaultTi, kDefaultTd});
        // "PID only really starts once every point has been measured."
        std::array<fatek::LoopInput, fatek::kLoopMaxPoints> in{};
        for (int i = 0; i < b_.points; ++i) {
            const int p = static_cast<int>(b_.sh) + i;
            const Point& pt = points_->at[static_cast<std::size_t>(p)];
            if (!pt.read_once) {
                stop(img);
                return;
            }
            // The PV of point p is TR + (p − Sm): the readings are contiguous.
            const auto at = b_.m.tr.index + static_cast<std::uint32_t>(p - b_.m.sm);
            in[static_cast<std::size_t>(i)] = {
                static_cast<std::int16_t>(img.word(b_.m.tr.area, at)), pt.broken};
        }
        const Factors f = Factors::read(img);
        loop_.set_gain(kFullScale / full_scale(tp, pl, f.fahrenheit, f.jis));
        write_bit(img, b_.ao1, loop_.run(ctx, b_.hc.read(img), in));
    }

    std::string_view mnemonic() const noexcept override { return "TSTC"; }

private:
    static void write_bit(image::Image& img, const std::optional<Device>& d, bool v) {
        if (d) img.write_bit(*d, v);
    }

    void stop(image::Image& img) {
        loop_.stop(img);
        write_bit(img, b_.ao1, false);
    }

    Bound b_;
    std::shared_ptr<Points> points_;
    std::vector<engine::Claim> claims_;
    ModuleCycle cycle_;
    fatek::TemperatureLoop loop_;
    bool prev_en_ = false;
};

}  // namespace

std::unique_ptr<engine::Instruction> make_tstc(const instructions::Entry& ic,
                                               const instructions::BindContext& ctx) {
    Bound b = bind(ic, ctx);
    Operands ops(ic, ctx);
    std::vector<engine::Claim> claims;
    if (b.valid) {
        auto mine = module_claims(b.m, "TSTC", kWorkingWords, b.where);
        const auto n = static_cast<std::uint32_t>(b.points);
        mine.push_back(
            {"or", {{b.l.out.area, b.l.out.index, n}, engine::ClaimKind::Output, "TSTC", b.where}});
        mine.push_back({"yh", {{Area::Y, b.yh.index, n}, engine::ClaimKind::Pwm, "TSTC", b.where}});
        refuse_shared(ops, mine);
        for (const auto& c : mine) claims.push_back(c.second);
    }
    const auto* fs = dynamic_cast<const Services*>(&ctx.services);
    if (b.valid && fs != nullptr) fs->contiguity->controlled(ops, b.m, b.sh, b.zh, b.where);
    auto points = fs != nullptr ? fs->points : std::make_shared<Points>();
    return std::make_unique<Tstc>(std::move(b), std::move(points), std::move(claims));
}

}  // namespace plcemu::profiles::fb
