#include "profiles/fb/tpsns.hpp"

#include <chrono>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "instructions/operands.hpp"
#include "profiles/fatek/operands.hpp"
#include "profiles/fb/conversion.hpp"
#include "profiles/fb/point_sample.hpp"
#include "profiles/fb/services.hpp"
#include "profiles/fb/shared_devices.hpp"
#include "profiles/fb/special_registers.hpp"
#include "profiles/fb/temperature_modules.hpp"

namespace plcemu::profiles::fb {

namespace {

using image::Area;
using image::Device;
using instructions::BitSource;
using instructions::Operands;
using namespace tpsns;

struct Bound {
    BitSource en;
    long long tp = 0;
    long long pl = 0;
    bool valid = false;  // tp 0–1 (K, J) and pl 0–3: the instruction runs
    int points = kDefaultPoints;
    Device tr;
    Device wr;
    std::optional<Device> err, alm;
    std::string where;
};

// With `temperature.modules` the FB-4AJ(K)xx gives the points, and its J/K type must be tp's.
int module_points(Operands& ops, const Bound& b) {
    const auto* fs = dynamic_cast<const Services*>(&ops.context().services);
    if (fs == nullptr || fs->modules.empty()) return kDefaultPoints;
    const TemperatureModule* m = multiplexed_module(fs->modules);
    if (m == nullptr) {
        const TemperatureModule& other = fs->modules.front();
        ops.fail("tp", "TPSNS measures an FB-4AJ(K)xx, but temperature.modules lists the " +
                           other.name + " at " + declared_at(other) +
                           " (an FB-4AJ(K)xx is used alone, without FB-2A…4 modules)");
    }
    if (b.valid && m->sensor != b.tp) {
        ops.fail("tp", std::to_string(b.tp) + (b.tp == tp::kK ? " (K)" : " (J)") +
                           " does not match the " + m->name + " at " + declared_at(*m));
    }
    return m->points;
}

Bound bind(const instructions::Entry& ic, const instructions::BindContext& ctx) {
    constexpr long long kAny = 2147483647LL;
    Operands ops(ic, ctx);
    Bound b;
    b.where = ic.where.text();
    b.en = ops.bit_source("en", true);
    // Any integer here; out of range the instruction reports ERR at run time.
    b.tp = ops.integer("tp", -kAny, kAny);
    b.pl = ops.integer("pl", -kAny, kAny);
    b.valid = (b.tp == tp::kK || b.tp == tp::kJ) && b.pl >= 0 && b.pl <= kLastPl;
    b.points = module_points(ops, b);
    b.tr = fatek::register_block(ops, "tr", static_cast<std::uint32_t>(b.points));
    b.wr = fatek::register_block(ops, "wr", kWorkingWords);
    b.err = ops.optional_bit_output("err");
    b.alm = ops.optional_bit_output("alm");
    ops.finish();
    return b;
}

class Tpsns final : public engine::Instruction {
public:
    Tpsns(Bound b,
          std::shared_ptr<Points> points,
          std::shared_ptr<TpsnsLink> link,
          std::vector<engine::Claim> claims)
        : b_(std::move(b)),
          points_(std::move(points)),
          link_(std::move(link)),
          claims_(std::move(claims)) {}

    void declare(engine::Declarations& out) const override {
        for (const auto& c : claims_) out.claims.push_back(c);
    }

    void execute(engine::ScanContext& ctx) noexcept override {
        image::Image& img = ctx.image;
        if (ctx.first_scan) {
            running_ = false;
            group_ = 0;
            for (int p = 0; p < b_.points; ++p) point(p).reset();
        }
        if (!b_.valid) {
            // tp or pl out of range: not executed, ERR ON.
            write_optional(img, b_.err, true);
            link_->running = false;
            return;
        }
        write_optional(img, b_.err, false);
        const bool en = b_.en.read(img);
        if (en) {
            measure(ctx);
        } else if (running_) {
            // EN falls: the points are no longer read (TPCTL stops); TR and R3968+p keep
            // their values.
            running_ = false;
            for (int p = 0; p < b_.points; ++p) {
                point(p).read_once = false;
                point(p).broken = false;
                point(p).clear_samples();
            }
        }
        link_->running = en;
        write_status(img);
    }

    std::string_view mnemonic() const noexcept override { return "TPSNS"; }

private:
    Point& point(int p) const noexcept { return points_->at[static_cast<std::size_t>(p)]; }

    int groups() const noexcept { return (b_.points + kInputs - 1) / kInputs; }

    // The four inputs sample in parallel, one group every R4004 ms: a round of N points takes
    // ⌈N/4⌉ × R4004 ms. The schedule keeps its pace across scans (no drift by the scan time).
    void measure(engine::ScanContext& ctx) noexcept {
        image::Image& img = ctx.image;
        const auto interval = std::chrono::duration_cast<engine::Duration>(
            std::chrono::milliseconds(img.word(Area::R, special::kTpsnsInterval)));
        if (!running_) {
            // EN rises: group 0 is sampled R4004 ms later.
            running_ = true;
            group_ = 0;
            next_ = ctx.now + interval;
            for (int p = 0; p < b_.points; ++p) point(p).read_once = false;
        }
        if (ctx.now < next_) return;
        TemperatureModules* modules = TemperatureModules::of(ctx);
        const int last = std::min(b_.points, (group_ + 1) * kInputs);
        for (int p = group_ * kInputs; p < last; ++p) {
            const engine::SensorSample s =
                modules != nullptr ? modules->sense(p) : engine::SensorSample{true, 0.0, 0.0};
            const int reading =
                sample_point(img, static_cast<int>(b_.tp), static_cast<int>(b_.pl), p, point(p), s);
            img.set_word(b_.tr.area, b_.tr.index + static_cast<std::uint32_t>(p),
                         static_cast<std::uint16_t>(reading));
        }
        group_ = (group_ + 1) % groups();
        next_ += interval;  // R4004 is read at each group
        if (next_ < ctx.now) next_ = ctx.now;
    }

    // WR+0/WR+1 broken, WR+2/WR+3 read once (points 0–15, 16–23); ALM = any broken.
    void write_status(image::Image& img) const noexcept {
        std::uint32_t broken = 0, read = 0;
        for (int p = 0; p < b_.points; ++p) {
            if (point(p).broken) broken |= 1u << p;
            if (point(p).read_once) read |= 1u << p;
        }
        const std::uint16_t words[kWorkingWords] = {
            static_cast<std::uint16_t>(broken & 0xFFFF), static_cast<std::uint16_t>(broken >> 16),
            static_cast<std::uint16_t>(read & 0xFFFF), static_cast<std::uint16_t>(read >> 16)};
        for (std::uint32_t w = 0; w < kWorkingWords; ++w)
            img.set_word(b_.wr.area, b_.wr.index + w, words[w]);
        write_optional(img, b_.alm, broken != 0);
    }

    Bound b_;
    std::shared_ptr<Points> points_;
    std::shared_ptr<TpsnsLink> link_;
    std::vector<engine::Claim> claims_;
    bool running_ = false;  // EN was 1 at the last scan
    int group_ = 0;         // the next group sampled
    engine::Duration next_{0};
};

}  // namespace

std::unique_ptr<engine::Instruction> make_tpsns(const instructions::Entry& ic,
                                                const instructions::BindContext& ctx) {
    Bound b = bind(ic, ctx);
    Operands ops(ic, ctx);
    using engine::ClaimKind;
    const auto n = static_cast<std::uint32_t>(b.points);
    const auto claim = [&](image::Range r, ClaimKind kind) {
        return engine::Claim{r, kind, "TPSNS", b.where};
    };
    std::vector<std::pair<const char*, engine::Claim>> mine = {
        {"wr", claim({b.wr.area, b.wr.index, kWorkingWords}, ClaimKind::Working)},
        {"tr", claim({b.tr.area, b.tr.index, n}, ClaimKind::Output)},
    };
    claim_bit(mine, "err", b.err, "TPSNS", b.where);
    claim_bit(mine, "alm", b.alm, "TPSNS", b.where);
    std::vector<engine::Claim> claims = refuse_shared(ops, mine);
    // The raw readings R3968+p of its points.
    claims.push_back({{Area::R, special::kRawReadings, n}, ClaimKind::Output, "TPSNS", b.where});
    const auto* fs = dynamic_cast<const Services*>(&ctx.services);
    auto points = fs != nullptr ? fs->points : std::make_shared<Points>();
    auto link = fs != nullptr ? fs->tpsns : std::make_shared<TpsnsLink>();
    link->sensor = b.valid ? static_cast<int>(b.tp) : 0;
    link->pl = b.valid ? static_cast<int>(b.pl) : 0;
    link->tr = b.tr;
    return std::make_unique<Tpsns>(std::move(b), std::move(points), std::move(link),
                                   std::move(claims));
}

}  // namespace plcemu::profiles::fb
