#include "profiles/vb/mbus.hpp"

#include <chrono>
#include <string>
#include <vector>

#include "instructions/operands.hpp"
#include "profiles/vb/blocks.hpp"
#include "profiles/vb/mbus_table.hpp"
#include "profiles/vb/specials.hpp"

namespace plcemu::profiles::vb {

namespace {

using image::Area;
using instructions::BitSource;
using instructions::Operands;
using mbus::Status;

// The table and the working area lie in D0–D7999 (VB manual FNC149 operand table).
constexpr std::uint32_t kWorkingWords = 4;
constexpr std::uint16_t kMaxSets = 255;
// S2 words.
constexpr std::uint32_t kStatus = 0;
constexpr std::uint32_t kSetInProgress = 1;
constexpr std::uint32_t kPasses = 2;
constexpr std::uint32_t kException = 3;
// D9129 counts 10 ms; 0 means 100 ms (VB manual FNC149).
constexpr auto kTimeoutUnit = std::chrono::milliseconds(10);
constexpr auto kDefaultTimeout = std::chrono::milliseconds(100);

struct Bound {
    BitSource en;
    std::uint32_t s1 = 0;                   // the table
    std::uint32_t s2 = 0;                   // the working area
    std::string where;                      // the entry's "file:line:col"
    const image::Naming* naming = nullptr;  // the profile's: octal areas, 32-bit counters
    std::vector<image::Range> read_only;    // program data (file registers): no read lands there
};

class Mbus final : public engine::Instruction {
public:
    explicit Mbus(Bound b)
        : b_(std::move(b)) {}

    void declare(engine::Declarations& out) const override {
        out.claims.push_back(
            {{Area::D, b_.s2, kWorkingWords}, engine::ClaimKind::Working, "MBUS", b_.where});
    }

    // S1's count and the sets it holds now, the master devices of each set that passes its
    // checks, and S2 (docs/profile-vb.md, "FNC149 MBUS").
    void describe(const image::Image& image, engine::Tags& out) const override {
        using engine::Number;
        const std::string at = ", MBUS at " + b_.where;
        out.push_back(
            {{Area::D, b_.s1, 1}, "MBUS S1+0 number of transfer sets" + at, Number::Unsigned});
        static const char* const kSet[mbus::kSetWords] = {
            "slave station",
            "command: 1 read, 2 write series, 3 write one",
            "length",
            "master device type",
            "master device number",
            "slave device type",
            "slave device number"};
        const std::uint16_t sets = sets_in(image);
        for (std::uint32_t k = 0; k < sets; ++k) {
            const std::string set = "MBUS set " + std::to_string(k + 1) + " ";
            for (std::uint32_t w = 0; w < mbus::kSetWords; ++w) {
                const std::uint32_t offset = 1 + mbus::kSetWords * k + w;
                std::string what = set + "S1+" + std::to_string(offset);
                what += ' ';
                what += kSet[w];
                out.push_back({{Area::D, b_.s1 + offset, 1}, what + at, Number::Unsigned});
            }
            const auto words = set_words(image, k);
            const mbus::Checked c =
                mbus::check_set(words, image.layout(), *b_.naming, b_.read_only);
            if (c.status != mbus::kNormal) continue;
            std::string what = set;
            what += c.transfer.read ? "data read from station " : "data written to station ";
            what += std::to_string(c.transfer.station);
            out.push_back({c.transfer.master, what + at});
        }
        static const char* const kWorking[kWorkingWords] = {
            "status (high byte) and station of the last failed transfer (low byte)",
            "set in progress", "completed passes", "last exception code"};
        for (std::uint32_t w = 0; w < kWorkingWords; ++w) {
            out.push_back({{Area::D, b_.s2 + w, 1},
                           "MBUS S2+" + std::to_string(w) + " " + kWorking[w] + at,
                           Number::Unsigned});
        }
    }

    void execute(engine::ScanContext& ctx) noexcept override {
        // A power-up, a reload or STOP->RUN starts the table afresh. The link may still hold a
        // request sent before a STOP (its completion never polled while the program did not
        // run): it is given up, or the link would refuse every request from then on.
        if (ctx.first_scan) {
            if (ctx.outbound != nullptr) ctx.outbound->abandon();
            s_ = State{};
        }
        image::Image& img = ctx.image;
        if (!b_.en.read(img)) {
            if (s_.running) stop(ctx);
            return;
        }
        if (!s_.running) {
            // EN rising: set 1, no exception seen yet.
            s_ = State{};
            s_.running = true;
            set_working(img, kException, 0);
        }
        // M9199 is ON for the one scan after a pass (VB manual FNC149).
        const bool pulsed = s_.pulsed;
        s_.pulsed = false;
        img.set_bit(Area::M, special::kMbusPass, false);
        engine::OutboundLink* link = ctx.outbound;
        if (link == nullptr) return;
        if (s_.in_flight) {
            const auto done = link->poll();
            if (!done) return;
            s_.in_flight = false;
            apply(img, *done);
            ++s_.set;
        }
        send_next(img, *link, pulsed);
    }

    std::string_view mnemonic() const noexcept override { return "MBUS"; }

private:
    struct State {
        bool running = false;     // EN was ON at the last execution
        bool in_flight = false;   // a request waits for its completion
        std::uint16_t set = 0;    // 0-based set whose turn it is
        bool pass_clean = true;   // every transfer of this pass succeeded
        bool pulsed = false;      // the last execution ended a pass (M9199 ON)
        mbus::Transfer transfer;  // the one in flight
    };

    void set_working(image::Image& img, std::uint32_t word, std::uint16_t v) const noexcept {
        img.set_word(Area::D, b_.s2 + word, v);
    }

    // EN falling: the request is given up, a late reply discarded, M9199 OFF (VB manual
    // FNC149: "the data transmission/receiving will be discontinued immediately").
    void stop(engine::ScanContext& ctx) noexcept {
        if (s_.in_flight && ctx.outbound != nullptr) ctx.outbound->abandon();
        s_ = State{};
        ctx.image.set_bit(Area::M, special::kMbusPass, false);
    }

    // S2+0: the status in the high byte, the station in the low byte; it stays until a pass in
    // which every transfer succeeded.
    void report(image::Image& img, Status status, std::uint16_t station) noexcept {
        set_working(img, kStatus, static_cast<std::uint16_t>(status << 8 | (station & 0xFF)));
        s_.pass_clean = false;
    }

    void apply(image::Image& img, const engine::OutboundCompletion& done) noexcept {
        const mbus::Transfer& t = s_.transfer;
        switch (done.status) {
            case engine::OutboundStatus::Reply:
                if (!t.read) return;
                for (std::uint32_t i = 0; i < t.count; ++i) {
                    const std::uint32_t index = t.master.start + i;
                    if (image::is_bit_area(t.master.area)) {
                        img.set_bit(t.master.area, index, done.values[i] != 0);
                    } else {
                        img.set_word(t.master.area, index, done.values[i]);
                    }
                }
                return;
            case engine::OutboundStatus::Exception:
                set_working(img, kException, done.exception);
                report(img, mbus::kAbnormal, t.station);
                return;
            case engine::OutboundStatus::TimedOut:
                report(img, mbus::kNoResponse, t.station);
                return;
            case engine::OutboundStatus::Malformed:
                report(img, mbus::kAbnormal, t.station);
                return;
        }
    }

    // The end of a pass, failed transfers or not: M9199 ON for a scan, S2+2 counts it, S2+0 is
    // cleared when nothing failed, and set 1 is next.
    void end_pass(image::Image& img) noexcept {
        img.set_bit(Area::M, special::kMbusPass, true);
        s_.pulsed = true;
        set_working(img, kPasses,
                    static_cast<std::uint16_t>(img.word(Area::D, b_.s2 + kPasses) + 1));
        if (s_.pass_clean) set_working(img, kStatus, 0);
        s_.set = 0;
        s_.pass_clean = true;
    }

    // The table's sets as S1+0 counts them, or 0 when the count is out of 1-255 or the sets
    // would run past D7999.
    std::uint16_t sets_in(const image::Image& img) const noexcept {
        const std::uint16_t sets = img.word(Area::D, b_.s1);
        if (sets < 1 || sets > kMaxSets || b_.s1 + 1 + mbus::kSetWords * sets > kBlockAreaEnd)
            return 0;
        return sets;
    }

    // The words of set `k` (0-based).
    std::array<std::uint16_t, mbus::kSetWords> set_words(const image::Image& img,
                                                         std::uint32_t k) const noexcept {
        std::array<std::uint16_t, mbus::kSetWords> words{};
        const std::uint32_t base = b_.s1 + 1 + mbus::kSetWords * k;
        for (std::uint32_t w = 0; w < mbus::kSetWords; ++w) words[w] = img.word(Area::D, base + w);
        return words;
    }

    // Sends the first set from the current one on that passes its checks; those that fail are
    // skipped with their status. A pass ends at most once per scan, and not in the scan that
    // turned the previous pulse OFF, so that M9199 is seen OFF between two passes.
    void send_next(image::Image& img, engine::OutboundLink& link, bool pulsed) noexcept {
        for (;;) {
            // The table, S1+0 included, is read again at every set's turn.
            const std::uint16_t sets = sets_in(img);
            if (sets == 0) {
                report(img, mbus::kNumberError, 0);
                s_.set = 0;
                return;
            }
            if (s_.set >= sets) {
                if (!pulsed) end_pass(img);
                return;
            }
            set_working(img, kSetInProgress, static_cast<std::uint16_t>(s_.set + 1));
            const auto words = set_words(img, s_.set);
            const mbus::Checked checked =
                mbus::check_set(words, img.layout(), *b_.naming, b_.read_only);
            if (checked.status == mbus::kNormal) {
                // A link still busy with an abandoned request: the set waits for the next scan.
                submit(img, link, checked.transfer);
                return;
            }
            report(img, checked.status, words[0]);
            ++s_.set;
        }
    }

    // Builds the request, the data to write sampled now, with D9129's time-out.
    void submit(image::Image& img, engine::OutboundLink& link, const mbus::Transfer& t) noexcept {
        engine::OutboundRequest r;
        r.station = t.station;
        r.function = t.function;
        r.address = t.address;
        r.quantity = t.count;
        const std::uint16_t timeout = img.word(Area::D, special::kMbusTimeout);
        r.timeout = timeout == 0 ? kDefaultTimeout : kTimeoutUnit * timeout;
        if (!t.read) {
            for (std::uint32_t i = 0; i < t.count; ++i) {
                const std::uint32_t index = t.master.start + i;
                r.values[i] = image::is_bit_area(t.master.area)
                                  ? static_cast<std::uint16_t>(img.bit(t.master.area, index))
                                  : img.word(t.master.area, index);
            }
        }
        if (!link.submit(r)) return;
        s_.transfer = t;
        s_.in_flight = true;
    }

    Bound b_;
    State s_;
};

}  // namespace

std::unique_ptr<engine::Instruction> make_mbus(const instructions::Entry& ic,
                                               const instructions::BindContext& ctx) {
    // "The MBUS instruction can be used once only in the program" (VB manual FNC149).
    for (const auto& c : ctx.earlier.claims) {
        if (c.mnemonic == "MBUS") {
            throw instructions::BindError(
                ic.where, "MBUS: a program may have one MBUS only; the first is at " + c.where);
        }
    }
    Operands ops(ic, ctx);
    Bound b;
    b.where = ic.where.text();
    b.naming = &ctx.naming;
    for (const auto& [range, why] : ctx.services.reserved_outputs) b.read_only.push_back(range);
    b.en = ops.bit_source("en", true);
    b.s1 = d_block(ops, "s1", "S1 (the table)", 1, Use::Read);
    b.s2 = d_block(ops, "s2", "S2 (the working area)", kWorkingWords, Use::Written);
    ops.finish();
    return std::make_unique<Mbus>(std::move(b));
}

}  // namespace plcemu::profiles::vb
