#include "profiles/fb/tpctl.hpp"

#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "instructions/operands.hpp"
#include "profiles/fatek/operands.hpp"
#include "profiles/fb/control_loop.hpp"
#include "profiles/fb/services.hpp"
#include "profiles/fb/shared_devices.hpp"

namespace plcemu::profiles::fb {

namespace {

using image::Area;
using image::Device;
using instructions::BitSource;
using instructions::Operands;
using namespace tpctl;

struct Bound {
    BitSource en;
    BitSource hc;
    long long sn = 0;
    long long zn = 0;
    bool valid = false;  // Sn 0–23, Zn 1–24, Sn + Zn ≤ 24: the instruction runs
    int points = 0;      // Zn when valid
    Device yn;
    Device wr;
    fatek::LoopBlocks l;  // sv, os, pr, ir, dr, or
    std::optional<Device> err, alm;
    std::string where;
};

// Sn + Zn within the instruction's range but past the installed FB-4AJ(K)xx's points: the chain
// is known at load.
void check_module(Operands& ops, const Bound& b) {
    const auto* fs = dynamic_cast<const Services*>(&ops.context().services);
    if (fs == nullptr || !b.valid) return;
    const TemperatureModule* m = multiplexed_module(fs->modules);
    if (m == nullptr || b.sn + b.zn <= m->points) return;
    ops.fail("zn", "sn " + std::to_string(b.sn) + " + zn " + std::to_string(b.zn) +
                       " reaches point " + std::to_string(b.sn + b.zn - 1) + ", but the " +
                       m->name + " at " + declared_at(*m) + " has points 0-" +
                       std::to_string(m->points - 1));
}

Bound bind(const instructions::Entry& ic, const instructions::BindContext& ctx) {
    constexpr long long kAny = 2147483647LL;
    Operands ops(ic, ctx);
    Bound b;
    b.where = ic.where.text();
    if (ops.has("md")) {
        ops.fail("md",
                 "not an operand of the FB's FUN86 TPCTL: it has no Md, its integral always "
                 "accumulates (md belongs to the FBs TPCTL, profile fbs)");
    }
    b.en = ops.bit_source("en", true);
    b.hc = ops.bit_source("hc", true);
    // Sn/Zn: any integer here; out of range the instruction reports ERR at run time.
    b.sn = ops.integer("sn", -kAny, kAny);
    b.zn = ops.integer("zn", -kAny, kAny);
    b.valid = b.sn >= 0 && b.sn <= kMaxPoints - 1 && b.zn >= 1 && b.zn <= kMaxPoints &&
              b.sn + b.zn <= kMaxPoints;
    b.points = b.valid ? static_cast<int>(b.zn) : 0;
    const auto span = static_cast<std::uint32_t>(b.points > 0 ? b.points : 1);
    b.yn = ops.device("yn", span, {Area::Y});
    fatek::bind_point_blocks(ops, span, b.l);
    b.wr = fatek::register_block(ops, "wr", kWorkingWords);
    b.err = ops.optional_bit_output("err");
    b.alm = ops.optional_bit_output("alm");
    ops.finish();
    ops.refuse_reserved("yn", {Area::Y, b.yn.index, span});
    check_module(ops, b);
    return b;
}

fatek::LoopBlocks loop_blocks(const Bound& b) {
    fatek::LoopBlocks l = b.l;
    l.y = b.yn;
    l.status = b.wr;
    l.first = static_cast<int>(b.sn);
    l.points = b.points;
    return l;
}

// Its devices for the load checks, each with its operand: what it writes — WR and OR every scan,
// PR/IR/DR at its first execution, Yn, ERR and ALM — and the settings SV and OS it only reads.
// With Sn/Zn out of range it writes ERR and ALM only.
std::vector<std::pair<const char*, engine::Claim>> written_and_read(const Bound& b) {
    using engine::ClaimKind;
    const auto n = static_cast<std::uint32_t>(b.points);
    const auto claim = [&](const Device& d, std::uint32_t count, ClaimKind kind) {
        return engine::Claim{{d.area, d.index, count}, kind, "TPCTL", b.where};
    };
    std::vector<std::pair<const char*, engine::Claim>> mine;
    if (b.valid) {
        mine = {
            {"wr", claim(b.wr, kWorkingWords, ClaimKind::Working)},
            {"or", claim(b.l.out, n, ClaimKind::Output)},
            {"yn", claim(b.yn, n, ClaimKind::Pwm)},
            {"pr", claim(b.l.pr, n, ClaimKind::Output)},
            {"ir", claim(b.l.ir, n, ClaimKind::Output)},
            {"dr", claim(b.l.dr, n, ClaimKind::Output)},
        };
    }
    claim_bit(mine, "err", b.err, "TPCTL", b.where);
    claim_bit(mine, "alm", b.alm, "TPCTL", b.where);
    if (b.valid) {
        mine.push_back({"sv", claim(b.l.sv, n, ClaimKind::Read)});
        mine.push_back({"os", claim(b.l.os, n, ClaimKind::Read)});
    }
    return mine;
}

class Tpctl final : public engine::Instruction {
public:
    Tpctl(Bound b,
          std::shared_ptr<Points> points,
          std::shared_ptr<TpsnsLink> tpsns,
          std::vector<engine::Claim> claims)
        : b_(std::move(b)),
          points_(std::move(points)),
          tpsns_(std::move(tpsns)),
          claims_(std::move(claims)),
          loop_(loop_blocks(b_)) {}

    void declare(engine::Declarations& out) const override {
        for (const auto& c : claims_) out.claims.push_back(c);
        // Y(yn + i) switches the heater of temperature channel sn + i (TPSNS point sn + i).
        for (int i = 0; i < b_.points; ++i) {
            Device y = b_.yn;
            y.index += static_cast<std::uint32_t>(i);
            out.actuators.push_back({static_cast<int>(b_.sn) + i, y});
        }
    }

    // Point i: PV at TPSNS's TR + Sn + i, SV, OR, Kc/Ti/Td/Os and WR's bits as
    // docs/profile-fb.md, "FUN86 TPCTL", gives them, and ALM, the instruction's control warning.
    void loops(const image::Image& image, engine::Loops& out) const override {
        Device pv = tpsns_->tr;
        pv.index += static_cast<std::uint32_t>(b_.sn);
        const fatek::LoopBlocks blocks = loop_blocks(b_);
        for (int i = 0; i < b_.points; ++i) {
            engine::Loop l = point_loop(image, blocks, "TPCTL", i, pv, tpsns_->sensor);
            if (b_.alm) l.alarms.push_back({"control warning (ALM)", *b_.alm, 0});
            out.push_back(std::move(l));
        }
    }

    void execute(engine::ScanContext& ctx) noexcept override {
        image::Image& img = ctx.image;
        if (ctx.first_scan) loop_.reset();
        if (!b_.valid) {
            // Sn or Zn out of range: not executed, ERR ON (FB manual FUN86).
            write_optional(img, b_.err, true);
            write_optional(img, b_.alm, false);
            return;
        }
        write_optional(img, b_.err, false);
        // The PV of point i is TPSNS's TR + Sn + i; PID waits for TPSNS's EN ("it must be
        // enabled, then, can the FUN86 start working").
        Device pv = tpsns_->tr;
        pv.index += static_cast<std::uint32_t>(b_.sn);
        const LoopSource src{pv, tpsns_->sensor, tpsns_->pl, tpsns_->running};
        const bool alarm = loop_.run(ctx, b_.en.read(img), b_.hc.read(img), *points_, src);
        write_optional(img, b_.alm, alarm);
    }

    std::string_view mnemonic() const noexcept override { return "TPCTL"; }

private:
    Bound b_;
    std::shared_ptr<Points> points_;
    std::shared_ptr<TpsnsLink> tpsns_;
    std::vector<engine::Claim> claims_;
    ControlLoop loop_;
};

}  // namespace

std::unique_ptr<engine::Instruction> make_tpctl(const instructions::Entry& ic,
                                                const instructions::BindContext& ctx) {
    Bound b = bind(ic, ctx);
    Operands ops(ic, ctx);
    const auto mine = written_and_read(b);
    std::vector<engine::Claim> claims = refuse_shared(ops, mine);
    const auto* fs = dynamic_cast<const Services*>(&ctx.services);
    if (b.valid && fs != nullptr) fs->controlled->claim(ops, "sn", "TPCTL", b.sn, b.zn, b.where);
    auto points = fs != nullptr ? fs->points : std::make_shared<Points>();
    auto tpsns = fs != nullptr ? fs->tpsns : std::make_shared<TpsnsLink>();
    return std::make_unique<Tpctl>(std::move(b), std::move(points), std::move(tpsns),
                                   std::move(claims));
}

}  // namespace plcemu::profiles::fb
