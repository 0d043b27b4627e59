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
#include "profiles/fatek/temperature_loop.hpp"
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

/// The operands of one TPCTL entry, checked.
struct Bound {
    BitSource en;
    BitSource hc;
    int md = 0;
    Device yn;
    long long sn = 0;
    long long zn = 0;
    bool valid = false;   // the Sn/Zn rule holds
    int points = 0;       // Zn when valid
    fatek::LoopBlocks l;  // sv, os, pr, ir, dr, or
    Device wr;
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
    fatek::bind_point_blocks(ops, span, b.l);
    b.wr = fatek::register_block(ops, "wr", kWorkingWords);
    b.err = ops.optional_bit_output("err");
    b.alm = ops.optional_bit_output("alm");
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
        {"sv", block(me.l.sv, me.points)}, {"os", block(me.l.os, me.points)},
        {"pr", block(me.l.pr, me.points)}, {"ir", block(me.l.ir, me.points)},
        {"dr", block(me.l.dr, me.points)}, {"or", block(me.l.out, me.points)}};
    for (const auto& [key, r] : own) {
        if (r.overlaps(wr)) {
            ops.fail(key, ops.format(r) + " overlaps this instruction's working registers " +
                              ops.format(wr));
        }
    }
    // The outputs it writes every scan would replace its own settings (`or` = `sv`), and a flag
    // inside its PWM outputs, or both flags on one bit, would be written twice a scan.
    const Range own_or = block(me.l.out, me.points);
    for (const auto& [key, r] : own) {
        if (std::string_view(key) != "or" && r.overlaps(own_or)) {
            ops.fail("or", ops.format(own_or) + " overlaps this instruction's " + key + " " +
                               ops.format(r));
        }
    }
    const Range own_y = block(me.yn, me.points);
    for (const auto& [key, flag] : {std::pair{"err", me.err}, std::pair{"alm", me.alm}}) {
        if (flag && own_y.overlaps({flag->area, flag->index, 1})) {
            ops.fail(key, ops.format({flag->area, flag->index, 1}) +
                              " is one of this instruction's PWM outputs " + ops.format(own_y));
        }
    }
    if (me.err && me.alm && me.err->area == me.alm->area && me.err->index == me.alm->index)
        ops.fail("alm", "alm is the same bit as err");
    // Each pair is checked once, at the later entry, against what the earlier ones own.
    const Range mine_or = block(me.l.out, me.points);
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
            case engine::ClaimKind::Read:
                break;  // no FBs instruction declares settings it reads
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

// FBs FUN86's figures (FBs manual §21.7): OR 0–16383, E in 0.1° straight into it, Kc/Ki/Td up
// to 9999, R4007 from 60 s, R4008 in 0.1° from 100, R4005 codes 0…5 → 1, 2, 4, 8, 16, 32 s, and
// the 7FFFh of a broken sensor is no temperature at all.
const fatek::LoopRules kRules{kFullScale, 9999, 60, 100, {1, 2, 4, 8, 16, 32}, false, false};

fatek::LoopBlocks loop_blocks(const Bound& b) {
    fatek::LoopBlocks l = b.l;
    l.y = b.yn;
    l.status = b.wr;
    l.first = static_cast<int>(b.sn);
    l.points = b.points;
    return l;
}

class Tpctl final : public engine::Instruction {
public:
    Tpctl(Bound b, std::optional<Device> table)
        : b_(std::move(b)),
          table_(table),
          loop_(&kRules, loop_blocks(b_), 1.0, b_.md == 0, 1) {}

    void declare(engine::Declarations& out) const override {
        if (!b_.valid) return;  // never executes, never writes
        const std::string at = b_.pos.text();
        out.claims.push_back(
            {block(b_.wr, kWorkingWords), engine::ClaimKind::Working, "TPCTL", at});
        out.claims.push_back({block(b_.l.out, b_.points), engine::ClaimKind::Output, "TPCTL", at});
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
            {&b_.l.sv, "setpoint, 0.1 degree"}, {&b_.l.os, "in-zone offset, 0.1 degree"},
            {&b_.l.pr, "Kc, 1-9999"},           {&b_.l.ir, "Ki, 0.01 repeats/min"},
            {&b_.l.dr, "Td, 0.01 min"},         {&b_.l.out, "PID output, 0-16383"}};
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

    void loops(const image::Image& image, engine::Loops& out) const override {
        const std::optional<Device> pv_start = pv_source(image);
        for (int i = 0; i < b_.points; ++i) {
            const auto k = static_cast<std::uint32_t>(i);
            auto at = [&](const Device& block) {
                Device d = block;
                d.index += k;
                return d;
            };
            engine::Loop l;
            l.name =
                "TPCTL point " + std::to_string(i) + " (channel " + std::to_string(b_.sn + i) + ")";
            l.channel = static_cast<int>(b_.sn + i);
            if (pv_start)
                l.pv = at(Device{pv_start->area,
                                 pv_start->index + static_cast<std::uint32_t>(b_.sn), false});
            l.sv = at(b_.l.sv);
            l.output = at(b_.l.out);
            l.scale = 0.1;
            l.unit = "°C";
            l.output_full = 16383;
            l.parameters = {{"Kc", at(b_.l.pr), "1-9999"},
                            {"Ki", at(b_.l.ir), "0.01 repeats/min"},
                            {"Td", at(b_.l.dr), "0.01 min"},
                            {"in-zone offset", at(b_.l.os), "0.1 °C"}};
            // WR+0/1 in zone, +2/3 warning, +5/6 over-temperature, +7/8 heater open: bit i%16 of
            // the word of points 0-15 or 16-31.
            const auto half = static_cast<std::uint32_t>(i / 16);
            const auto bit = static_cast<std::uint8_t>(i % 16);
            auto flag = [&](const char* name, std::uint32_t word) {
                Device w = b_.wr;
                w.index += word + half;
                return engine::LoopFlag{name, w, bit};
            };
            l.alarms = {flag("in zone", 0), flag("warning", 2), flag("over temperature", 5),
                        flag("heater open", 7)};
            out.push_back(std::move(l));
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
        // R4005 is read only at the rise: changes while EN = 1 wait for the next (manual note 1).
        if (rising) loop_.latch_timing(img);
        if (!en) {
            stop(img);
            return;
        }
        // "When performing the instruction the first time": default gains for every point whose
        // PR is still 0 (a retained, tuned PR is kept).
        loop_.first_execution(img, {kDefaultKc, kDefaultKi, kDefaultTd});
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
        loop_.stop(img);
        write_bit(img, b_.alm, false);
    }

    // A reading of 7FFFh is a broken sensor: no PV (FBs manual §21.3).
    void run(engine::ScanContext& ctx, const Device& pv_start) {
        image::Image& img = ctx.image;
        std::array<fatek::LoopInput, fatek::kLoopMaxPoints> in{};
        for (int i = 0; i < b_.points; ++i) {
            const std::uint16_t raw =
                img.word(pv_start.area, pv_start.index + static_cast<std::uint32_t>(b_.sn + i));
            in[static_cast<std::size_t>(i)] = {static_cast<std::int16_t>(raw),
                                               raw == kBrokenReading};
        }
        write_bit(img, b_.alm, loop_.run(ctx, b_.hc.read(img), in));
    }

    Bound b_;
    std::optional<Device> table_;
    fatek::TemperatureLoop loop_;
    bool prev_en_ = false;
};

}  // namespace

std::unique_ptr<engine::Instruction> make_tpctl(const instructions::Entry& ic,
                                                const BindContext& ctx) {
    Bound b = bind(ic, ctx);
    Operands ops(ic, ctx);
    ops.refuse_reserved("yn", block(b.yn, b.points));
    check_overlaps(b, ic, ctx);
    const auto* fs = dynamic_cast<const Services*>(&ctx.services);
    return std::make_unique<Tpctl>(std::move(b),
                                   fs ? fs->temperature_table : std::optional<Device>{});
}

}  // namespace plcemu::profiles::fbs
