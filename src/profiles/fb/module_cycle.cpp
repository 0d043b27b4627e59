#include "profiles/fb/module_cycle.hpp"

#include <chrono>
#include <string>
#include <utility>
#include <vector>

#include "profiles/fatek/operands.hpp"
#include "profiles/fb/conversion.hpp"
#include "profiles/fb/point_sample.hpp"
#include "profiles/fb/services.hpp"
#include "profiles/fb/special_registers.hpp"
#include "profiles/fb/temperature_modules.hpp"

namespace plcemu::profiles::fb {

namespace {

using image::Area;
using image::Device;
namespace sp = special;
using namespace cycle;

bool valid_operands(long long tp, long long pl, long long sm) {
    return tp >= 0 && tp <= tp::kLast && pl >= 0 && pl <= kLastPl && sm >= 0 && sm <= 28 &&
           sm % kPoints == 0;
}

// With a `temperature.modules` chain, the module at Sm is the one Tp names (docs/profile-fb.md,
// "Temperature modules").
void check_module(instructions::Operands& ops, const ModuleOperands& m) {
    const auto* fs = dynamic_cast<const Services*>(&ops.context().services);
    if (fs == nullptr || fs->modules.empty() || !m.valid) return;
    const auto j = static_cast<std::size_t>(m.sm / kPoints);
    if (j >= fs->modules.size()) {
        ops.fail("sm", std::to_string(m.sm) + " is point " + std::to_string(m.sm) + " of module " +
                           std::to_string(j + 1) + ", but temperature.modules lists " +
                           std::to_string(fs->modules.size()));
    }
    const TemperatureModule& module = fs->modules[j];
    if (module.multiplexed || module.sensor != m.tp) {
        ops.fail("tp", std::to_string(m.tp) + " does not match the " + module.name + " at " +
                           declared_at(module) + ", the module of points " +
                           std::to_string(j * kPoints) + "-" +
                           std::to_string(j * kPoints + kPoints - 1));
    }
}

std::uint32_t offset(const Device& d, int i) { return d.index + static_cast<std::uint32_t>(i); }

}  // namespace

ModuleOperands bind_module(instructions::Operands& ops, std::uint32_t wr_words) {
    constexpr long long kAny = 2147483647LL;
    ModuleOperands m;
    m.tp = ops.integer("tp", -kAny, kAny);
    m.pl = ops.integer("pl", -kAny, kAny);
    m.sm = ops.integer("sm", -kAny, kAny);
    m.valid = valid_operands(m.tp, m.pl, m.sm);
    m.ym = ops.device("ym", kRelays, {Area::Y});
    m.ar = ops.device("ar", 1, {Area::R});
    if (m.ar.index < kFirstInput || m.ar.index > kLastInput) {
        ops.fail("ar", "expected an IR register R3840-R3903 (the module's analog input), got " +
                           ops.format({Area::R, m.ar.index, 1}));
    }
    m.tr = fatek::register_block(ops, "tr", kPoints);
    m.wr = fatek::register_block(ops, "wr", wr_words);
    ops.refuse_reserved("ym", {Area::Y, m.ym.index, kRelays});
    check_module(ops, m);
    return m;
}

std::vector<std::pair<const char*, engine::Claim>> module_claims(const ModuleOperands& m,
                                                                 std::string_view mnemonic,
                                                                 std::uint32_t wr_words,
                                                                 const std::string& where) {
    using engine::ClaimKind;
    const auto claim = [&](image::Range r, ClaimKind kind) {
        return engine::Claim{r, kind, mnemonic, where};
    };
    return {
        {"wr", claim({m.wr.area, m.wr.index, wr_words}, ClaimKind::Working)},
        {"tr", claim({m.tr.area, m.tr.index, cycle::kPoints}, ClaimKind::Output)},
        {"ym", claim({Area::Y, m.ym.index, cycle::kRelays}, ClaimKind::Output)},
        {"ar", claim({Area::R, m.ar.index, 1}, ClaimKind::Output)},
        // Two instructions on one module (the same Sm) would write the same raw readings.
        {"sm",
         claim({Area::R, special::kRawReadings + static_cast<std::uint32_t>(m.sm), cycle::kPoints},
               ClaimKind::Output)},
    };
}

ModuleCycle::ModuleCycle(const ModuleOperands& ops, std::shared_ptr<Points> points)
    : ops_(ops),
      points_(std::move(points)) {}

Point& ModuleCycle::point(int k) const noexcept {
    return points_->at[static_cast<std::size_t>(ops_.sm + k)];
}

void ModuleCycle::reset() noexcept {
    running_ = false;
    selected_ = 0;
    next_ = engine::Duration{0};
    // An instruction whose Sm is out of range has no points (and never runs).
    if (!ops_.valid) return;
    for (int k = 0; k < kPoints; ++k) point(k).reset();
}

std::uint16_t ModuleCycle::broken_bits() const noexcept {
    unsigned bits = 0;
    for (int k = 0; k < kPoints; ++k) bits |= point(k).broken ? 1u << k : 0u;
    return static_cast<std::uint16_t>(bits);
}

void ModuleCycle::write_status(image::Image& img) const noexcept {
    unsigned read = 0;
    for (int k = 0; k < kPoints; ++k) read |= point(k).read_once ? 1u << k : 0u;
    img.set_word(ops_.wr.area, ops_.wr.index, broken_bits());
    img.set_word(ops_.wr.area, offset(ops_.wr, 1), static_cast<std::uint16_t>(read));
    img.set_word(ops_.wr.area, offset(ops_.wr, 2),
                 static_cast<std::uint16_t>(running_ ? selected_ : 0));
    for (int w = 3; w < static_cast<int>(kWorkingWords); ++w)
        img.set_word(ops_.wr.area, offset(ops_.wr, w), 0);
}

void ModuleCycle::stop() noexcept {
    running_ = false;
    for (int k = 0; k < kPoints; ++k) {
        Point& p = point(k);
        p.read_once = false;
        p.broken = false;
        p.clear_samples();
    }
}

void ModuleCycle::sample(engine::ScanContext& ctx, int k, const engine::SensorSample& s) noexcept {
    const int p = static_cast<int>(ops_.sm) + k;
    const int reading = sample_point(ctx.image, static_cast<int>(ops_.tp),
                                     static_cast<int>(ops_.pl), p, point(k), s);
    ctx.image.set_word(ops_.tr.area, offset(ops_.tr, k), static_cast<std::uint16_t>(reading));
}

void ModuleCycle::run(engine::ScanContext& ctx, bool en) noexcept {
    image::Image& img = ctx.image;
    if (!en) {
        if (running_) stop();
        for (std::uint32_t i = 0; i < kRelays; ++i) img.set_bit(Area::Y, ops_.ym.index + i, false);
        write_status(img);
        return;
    }
    const auto interval = [&] {
        return std::chrono::duration_cast<engine::Duration>(
            std::chrono::milliseconds(img.word(Area::R, sp::kPointInterval)));
    };
    if (!running_) {
        // EN rises: point 0 is selected, and sampled R4014 ms later.
        running_ = true;
        selected_ = 0;
        next_ = ctx.now + interval();
        for (int k = 0; k < kPoints; ++k) point(k).read_once = false;
    }
    TemperatureModules* modules = TemperatureModules::of(ctx);
    const int p = static_cast<int>(ops_.sm) + selected_;
    const engine::SensorSample s =
        modules != nullptr ? modules->sense(p) : engine::SensorSample{true, 0.0, 0.0};
    // AR, the module's third input, shows the selected point; inputs 1 and 2 read 0 here.
    img.set_word(Area::R, ops_.ar.index,
                 static_cast<std::uint16_t>(
                     module_raw(img, static_cast<int>(ops_.tp), static_cast<int>(ops_.pl), p, s)));
    for (std::uint32_t back = 1; back <= 2; ++back) {
        if (ops_.ar.index >= kFirstInput + back) img.set_word(Area::R, ops_.ar.index - back, 0);
    }
    if (ctx.now >= next_) {
        sample(ctx, selected_, s);
        selected_ = (selected_ + 1) % kPoints;
        next_ = ctx.now + interval();  // R4014 is read at each selection
    }
    for (std::uint32_t i = 0; i < kRelays; ++i) {
        const bool on = static_cast<int>(i / 2) == selected_;
        img.set_bit(Area::Y, ops_.ym.index + i, on);
    }
    write_status(img);
}

}  // namespace plcemu::profiles::fb
