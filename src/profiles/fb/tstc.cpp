#include "profiles/fb/tstc.hpp"

#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "instructions/operands.hpp"
#include "profiles/fatek/operands.hpp"
#include "profiles/fatek/temperature_loop.hpp"
#include "profiles/fb/control_loop.hpp"
#include "profiles/fb/module_cycle.hpp"
#include "profiles/fb/services.hpp"
#include "profiles/fb/shared_devices.hpp"

namespace plcemu::profiles::fb {

namespace {

using image::Area;
using image::Device;
using instructions::BitSource;
using instructions::Operands;
using namespace tstc;

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
    b.err = ops.optional_bit_output("err");
    b.ao0 = ops.optional_bit_output("ao0");
    b.ao1 = ops.optional_bit_output("ao1");
    ops.finish();
    ops.refuse_reserved("yh", {Area::Y, b.yh.index, span});
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

// Its devices for the load checks, each with its operand: what it writes — its module's (as
// TP4's), OR and Yh every scan, PR/IR/DR at its first execution, ERR, AO0 and AO1 — and the
// settings SV and OS it only reads. With an operand out of range it writes ERR only.
std::vector<std::pair<const char*, engine::Claim>> written_and_read(const Bound& b) {
    using engine::ClaimKind;
    const auto n = static_cast<std::uint32_t>(b.points);
    const auto claim = [&](const Device& d, ClaimKind kind) {
        return engine::Claim{{d.area, d.index, n}, kind, "TSTC", b.where};
    };
    std::vector<std::pair<const char*, engine::Claim>> mine;
    if (b.valid) {
        mine = module_claims(b.m, "TSTC", kWorkingWords, b.where);
        mine.push_back({"or", claim(b.l.out, ClaimKind::Output)});
        mine.push_back({"yh", claim(b.yh, ClaimKind::Pwm)});
        mine.push_back({"pr", claim(b.l.pr, ClaimKind::Output)});
        mine.push_back({"ir", claim(b.l.ir, ClaimKind::Output)});
        mine.push_back({"dr", claim(b.l.dr, ClaimKind::Output)});
    }
    claim_bit(mine, "err", b.err, "TSTC", b.where);
    if (b.valid) {
        claim_bit(mine, "ao0", b.ao0, "TSTC", b.where);
        claim_bit(mine, "ao1", b.ao1, "TSTC", b.where);
        mine.push_back({"sv", claim(b.l.sv, ClaimKind::Read)});
        mine.push_back({"os", claim(b.l.os, ClaimKind::Read)});
    }
    return mine;
}

class Tstc final : public engine::Instruction {
public:
    Tstc(Bound b, std::shared_ptr<Points> points, std::vector<engine::Claim> claims)
        : b_(std::move(b)),
          points_(points),
          claims_(std::move(claims)),
          cycle_(b_.m, std::move(points)),
          loop_(loop_blocks(b_)) {}

    void declare(engine::Declarations& out) const override {
        for (const auto& c : claims_) out.claims.push_back(c);
        // Y(yh + i) switches the heater of temperature channel sh + i.
        for (int i = 0; i < b_.points; ++i) {
            Device y = b_.yh;
            y.index += static_cast<std::uint32_t>(i);
            out.actuators.push_back({static_cast<int>(b_.sh) + i, y});
        }
    }

    // Point i (absolute point Sh + i): PV at TR + (Sh + i − Sm), SV, OR, Kc/Ti/Td/Os and the
    // loop's WR+8…WR+16 bits as docs/profile-fb.md, "FUN73 TSTC", gives them; a point of its own
    // module also WR+0's broken bit, and every point AO1, the instruction's control warning.
    void loops(const image::Image& image, engine::Loops& out) const override {
        Device pv = b_.m.tr;
        pv.index += static_cast<std::uint32_t>(b_.sh - b_.m.sm);
        const fatek::LoopBlocks blocks = loop_blocks(b_);
        for (int i = 0; i < b_.points; ++i) {
            engine::Loop l = point_loop(image, blocks, "TSTC", i, pv, static_cast<int>(b_.m.tp));
            // WR+0 bit k: point Sm + k of its own module broken.
            const long long k = b_.sh + i - b_.m.sm;
            if (k < cycle::kPoints)
                l.alarms.push_back({"sensor broken", b_.m.wr, static_cast<std::uint8_t>(k)});
            if (b_.ao1) l.alarms.push_back({"control warning (AO1)", *b_.ao1, 0});
            out.push_back(std::move(l));
        }
    }

    void execute(engine::ScanContext& ctx) noexcept override {
        image::Image& img = ctx.image;
        if (ctx.first_scan) {
            cycle_.reset();
            loop_.reset();
        }
        if (!b_.valid) {
            // Tp, Pl, Sm, Sh or Zh out of range: not executed, ERR ON (FB manual FUN73).
            write_optional(img, b_.err, true);
            return;
        }
        write_optional(img, b_.err, false);
        const bool en = b_.en.read(img);
        cycle_.run(ctx, en);
        write_optional(img, b_.ao0, cycle_.broken_bits() != 0);
        // The PV of point p is TR + (p − Sm): the readings are contiguous.
        Device pv = b_.m.tr;
        pv.index += static_cast<std::uint32_t>(b_.sh - b_.m.sm);
        const LoopSource src{pv, static_cast<int>(b_.m.tp), static_cast<int>(b_.m.pl), true};
        write_optional(img, b_.ao1, loop_.run(ctx, en, b_.hc.read(img), *points_, src));
    }

    std::string_view mnemonic() const noexcept override { return "TSTC"; }

private:
    Bound b_;
    std::shared_ptr<Points> points_;
    std::vector<engine::Claim> claims_;
    ModuleCycle cycle_;
    ControlLoop loop_;
};

}  // namespace

std::unique_ptr<engine::Instruction> make_tstc(const instructions::Entry& ic,
                                               const instructions::BindContext& ctx) {
    Bound b = bind(ic, ctx);
    Operands ops(ic, ctx);
    const auto mine = written_and_read(b);
    std::vector<engine::Claim> claims = refuse_shared(ops, mine);
    const auto* fs = dynamic_cast<const Services*>(&ctx.services);
    if (b.valid && fs != nullptr) {
        fs->contiguity->controlled(ops, b.m, b.sh, b.zh, b.where);
        fs->controlled->claim(ops, "sh", "TSTC", b.sh, b.zh, b.where);
    }
    auto points = fs != nullptr ? fs->points : std::make_shared<Points>();
    return std::make_unique<Tstc>(std::move(b), std::move(points), std::move(claims));
}

}  // namespace plcemu::profiles::fb
