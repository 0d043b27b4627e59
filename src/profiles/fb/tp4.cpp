#include "profiles/fb/tp4.hpp"

#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "instructions/operands.hpp"
#include "profiles/fb/module_cycle.hpp"
#include "profiles/fb/services.hpp"
#include "profiles/fb/shared_devices.hpp"

namespace plcemu::profiles::fb {

namespace {

using image::Area;
using image::Device;
using instructions::BitSource;
using instructions::Operands;

class Tp4 final : public engine::Instruction {
public:
    Tp4(BitSource en,
        ModuleCycle cycle,
        std::optional<Device> err,
        std::optional<Device> alm,
        std::vector<engine::Claim> claims)
        : en_(en),
          cycle_(std::move(cycle)),
          err_(err),
          alm_(alm),
          claims_(std::move(claims)) {}

    void declare(engine::Declarations& out) const override {
        for (const auto& c : claims_) out.claims.push_back(c);
    }

    void execute(engine::ScanContext& ctx) noexcept override {
        image::Image& img = ctx.image;
        if (ctx.first_scan) cycle_.reset();
        if (!cycle_.operands().valid) {
            // Tp, Pl or Sm out of range: not executed, ERR ON (FB manual FUN73).
            write_optional(img, err_, true);
            return;
        }
        write_optional(img, err_, false);
        cycle_.run(ctx, en_.read(img));
        write_optional(img, alm_, cycle_.broken_bits() != 0);
    }

    std::string_view mnemonic() const noexcept override { return "TP4"; }

private:
    BitSource en_;
    ModuleCycle cycle_;
    std::optional<Device> err_;
    std::optional<Device> alm_;
    std::vector<engine::Claim> claims_;
};

}  // namespace

std::unique_ptr<engine::Instruction> make_tp4(const instructions::Entry& ic,
                                              const instructions::BindContext& ctx) {
    Operands ops(ic, ctx);
    const BitSource en = ops.bit_source("en", true);
    const ModuleOperands m = bind_module(ops, cycle::kWorkingWords);
    const std::optional<Device> err = ops.optional_bit_output("err");
    const std::optional<Device> alm = ops.optional_bit_output("alm");
    ops.finish();
    // What it writes: its module's devices while Tp/Pl/Sm are valid, ERR always, ALM only then.
    const std::string where = ic.where.text();
    std::vector<std::pair<const char*, engine::Claim>> mine;
    if (m.valid) mine = module_claims(m, "TP4", cycle::kWorkingWords, where);
    claim_bit(mine, "err", err, "TP4", where);
    if (m.valid) claim_bit(mine, "alm", alm, "TP4", where);
    std::vector<engine::Claim> claims = refuse_shared(ops, mine);
    const auto* fs = dynamic_cast<const Services*>(&ctx.services);
    if (m.valid && fs != nullptr) fs->contiguity->measured(ops, m, where);
    auto points = fs != nullptr ? fs->points : std::make_shared<Points>();
    return std::make_unique<Tp4>(en, ModuleCycle(m, std::move(points)), err, alm,
                                 std::move(claims));
}

}  // namespace plcemu::profiles::fb
