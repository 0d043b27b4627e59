// A program from the statements of a listing: the rung structure checked, bit logic built here,
// function instructions through the family's table with the rung as their enable.

#include <cctype>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "cnt.hpp"
#include "operands.hpp"
#include "pls.hpp"
#include "relation.hpp"
#include "rst.hpp"
#include "rung.hpp"
#include "tmr.hpp"
#include "plcemu/image/excerpt.hpp"
#include "plcemu/instructions/listing.hpp"

namespace plcemu::instructions {

namespace {

using image::Area;

// Builds one program, statement by statement, keeping what the structure checks need.
class ListingBuilder {
public:
    ListingBuilder(const Dialect& dialect,
                   const Table& table,
                   const image::Layout& layout,
                   const image::Naming& naming,
                   const Services& services,
                   std::vector<ListingWarning>* warnings,
                   engine::Tags* operands)
        : dialect_(dialect),
          table_(table),
          base_{layout, naming, services, earlier_, operands, nullptr},
          warnings_(warnings),
          rung_(std::make_shared<Rung>()) {}

    engine::Program build(const std::vector<Statement>& statements) {
        engine::Program p;
        p.reserve(statements.size());
        for (const auto& s : statements) {
            // NOPs may follow END, as an FX program's unused steps do.
            const bool nop = s.function == nullptr && s.spelling.step == Step::Nop;
            if (ended_ && !nop) {
                throw BindError(s.where, s.mnemonic + ": after END (END ends the program at " +
                                             end_where_.text() + ")");
            }
            add(s, p);
            // What each statement drives and owns, for the checks of the ones after it.
            if (p.size() > declared_) p.back()->declare(earlier_);
            declared_ = p.size();
        }
        finish();
        // A program of many double coils says so in one more line, not in one each.
        if (warnings_ != nullptr && double_coils_ > kMaxListingWarnings) {
            warnings_->push_back(
                {statements.front().where, std::to_string(double_coils_ - kMaxListingWarnings) +
                                               " more double coils in this program"});
        }
        return p;
    }

private:
    [[noreturn]] void fail(const Statement& s, const std::string& message) const {
        throw BindError(s.where, s.mnemonic + ": " + message);
    }

    // ANB, ORB, INV, TU, TD, MPS, MRD, MPP, NOP and END stand alone.
    void no_operand(const Statement& s) const {
        if (!s.operands.empty() || !s.named.empty()) fail(s, "takes no operand");
    }

    // An Entry for the operand checks of Operands: the statement's operands under `keys`.
    Entry entry_of(const Statement& s, std::initializer_list<const char*> keys) const {
        if (s.operands.size() != keys.size() || !s.named.empty()) {
            std::string want;
            for (const char* k : keys) want += std::string(want.empty() ? "" : " ") + k;
            fail(s, "expected " + std::to_string(keys.size()) + " operand" +
                        (keys.size() == 1 ? "" : "s") + " (" + want + "), got " +
                        std::to_string(s.operands.size() + s.named.size()));
        }
        Entry e{s.mnemonic, s.where, {}, s.step, true};
        auto it = s.operands.begin();
        for (const char* k : keys) e.operands.emplace_back(k, *it++);
        return e;
    }

    BindContext context() const {
        BindContext ctx = base_;
        ctx.rung = &rung_->result;
        return ctx;
    }

    void need_rung(const Statement& s) const {
        if (!open_) {
            fail(s, dialect_.networks ? "no network is open (a network starts with ORG)"
                                      : "no rung is open (a rung starts with LD)");
        }
    }

    // An output of the rung: every block LD opened must be closed.
    void output(const Statement& s) {
        need_rung(s);
        if (blocks_ > 0) {
            fail(s, std::to_string(blocks_) + " block" + (blocks_ == 1 ? "" : "s") +
                        " opened by LD not joined (" + block_ops() + ")");
        }
        after_output_ = true;
    }

    std::string block_ops() const {
        std::string names;
        for (const auto& [k, v] : dialect_.words) {
            if (v.step == Step::AndBlock || v.step == Step::OrBlock)
                names += (names.empty() ? "" : ", ") + k;
        }
        return names;
    }

    // A new rung starts: the one before must be complete.
    void new_rung(const Statement& s) {
        if (open_ && !after_output_) {
            fail(s, "the rung before (from " + rung_where_.text() + ") has no output");
        }
        if (branches_ > 0) {
            fail(s, "a new rung starts with " + std::to_string(branches_) +
                        " result(s) left on the branch stack (MPP takes the last one)");
        }
        open_ = true;
        after_output_ = false;
        rung_where_ = s.where;
    }

    // Is `text` a temporary relay (FATEK's TR3)? Its number then.
    std::optional<int> temporary(const Statement& s, const Operand& op) const {
        if (dialect_.temporary.empty()) return std::nullopt;
        std::string u;
        for (const char c : op.text)
            u += static_cast<char>(std::toupper(static_cast<unsigned char>(c)));
        if (u.compare(0, dialect_.temporary.size(), dialect_.temporary) != 0) return std::nullopt;
        const std::string n = u.substr(dialect_.temporary.size());
        if (n.empty() || n.find_first_not_of("0123456789") != std::string::npos || n.size() > 3)
            return std::nullopt;
        const int v = std::stoi(n);
        if (v >= dialect_.temporaries) {
            throw BindError(op.where, s.mnemonic + ": " + std::string(dialect_.temporary) + n +
                                          ": there are " + std::to_string(dialect_.temporaries) +
                                          " (" + std::string(dialect_.temporary) + "0–" +
                                          std::string(dialect_.temporary) +
                                          std::to_string(dialect_.temporaries - 1) + ")");
        }
        return v;
    }

    ContactSource contact_source(const Statement& s) const {
        ContactSource src;
        src.contact = s.spelling.contact;
        const BindContext ctx = context();
        if (s.spelling.contact == Contact::Compare) {
            const Entry e = entry_of(s, {"s1", "s2"});
            Operands ops(e, ctx);
            src.relation = *relation_of(s.spelling.relation);
            src.s1 = ops.word_source("s1");
            src.s2 = ops.word_source("s2");
            ops.finish();
            return src;
        }
        const Entry e = entry_of(s, {"s"});
        Operands ops(e, ctx);
        src.device = ops.device("s", 1, {Area::X, Area::Y, Area::M, Area::S, Area::T, Area::C});
        ops.finish();
        return src;
    }

    void add(const Statement& s, engine::Program& p) {
        if (s.function != nullptr) return function(s, p);
        const std::string_view name = dialect_.words.find(s.mnemonic)->first;
        switch (s.spelling.step) {
            case Step::Network:
                new_rung(s);
                p.push_back(make_contact(rung_, name, Join::Start, 0, contact_source(s)));
                return;
            case Step::Load:
                return load(s, name, p);
            case Step::And:
            case Step::Or:
                need_rung(s);
                after_output_ = false;
                p.push_back(make_contact(rung_, name,
                                         s.spelling.step == Step::And ? Join::And : Join::Or, 0,
                                         contact_source(s)));
                return;
            case Step::AndBlock:
            case Step::OrBlock:
                need_rung(s);
                no_operand(s);
                if (blocks_ == 0) fail(s, "no block opened by LD to join");
                --blocks_;
                after_output_ = false;
                p.push_back(make_rung_op(
                    rung_, name,
                    s.spelling.step == Step::AndBlock ? RungOp::AndBlock : RungOp::OrBlock,
                    blocks_));
                return;
            case Step::Push:
            case Step::Read:
            case Step::Pop:
                return branch(s, name, p);
            case Step::Invert:
            case Step::RisingResult:
            case Step::FallingResult: {
                need_rung(s);
                no_operand(s);
                const RungOp op = s.spelling.step == Step::Invert         ? RungOp::Invert
                                  : s.spelling.step == Step::RisingResult ? RungOp::Rising
                                                                          : RungOp::Falling;
                p.push_back(make_rung_op(rung_, name, op, 0));
                return;
            }
            case Step::Out:
            case Step::OutNot:
            case Step::Set:
                return coil(s, name, p);
            case Step::Reset: {
                output(s);
                Entry e = entry_of(s, {"d"});
                if (s.spelling.pulse) e.operands.emplace_back("p", Operand{"true", s.where});
                p.push_back(make_rst(e, context()));
                return;
            }
            case Step::PulseRising:
            case Step::PulseFalling: {
                output(s);
                const Entry e = entry_of(s, {"d"});
                p.push_back(s.spelling.step == Step::PulseRising ? make_pls(e, context())
                                                                 : make_plf(e, context()));
                return;
            }
            case Step::Timer:
                output(s);
                p.push_back(make_tmr(preset_entry(s, "t"), context()));
                return;
            case Step::Counter:
                output(s);
                p.push_back(make_cnt(preset_entry(s, "c"), context()));
                return;
            case Step::MasterControl:
                return master_control(s, p);
            case Step::MasterReset:
                return master_reset(s, p);
            case Step::Nop:
                // A step of its own (the step numbers after it count it), anywhere.
                no_operand(s);
                return;
            case Step::End:
                no_operand(s);
                ended_ = true;
                end_where_ = s.where;
                return;
        }
    }

    void load(const Statement& s, std::string_view name, engine::Program& p) {
        if (s.operands.size() == 1 && s.named.empty()) {
            if (const auto tr = temporary(s, s.operands.front())) {
                need_rung(s);
                after_output_ = false;
                p.push_back(make_rung_op(rung_, "LD", RungOp::Restore, *tr));
                return;
            }
        }
        if (dialect_.networks) need_rung(s);
        if (!open_ || (after_output_ && !dialect_.networks)) {
            new_rung(s);
            p.push_back(make_contact(rung_, name, Join::Start, 0, contact_source(s)));
            return;
        }
        if (blocks_ >= Rung::kBlocks) {
            fail(s, "more than " + std::to_string(Rung::kBlocks) + " blocks open at once");
        }
        after_output_ = false;
        p.push_back(make_contact(rung_, name, Join::Block, blocks_, contact_source(s)));
        ++blocks_;
    }

    void branch(const Statement& s, std::string_view name, engine::Program& p) {
        need_rung(s);
        no_operand(s);
        if (s.spelling.step == Step::Push) {
            if (branches_ >= Rung::kBranches) {
                fail(s, "the branch stack holds " + std::to_string(Rung::kBranches) + " results");
            }
            p.push_back(make_rung_op(rung_, name, RungOp::Push, branches_++));
            return;
        }
        if (branches_ == 0) fail(s, "the branch stack is empty (MPS puts a result on it)");
        if (s.spelling.step == Step::Pop) --branches_;
        after_output_ = false;
        const int at = s.spelling.step == Step::Pop ? branches_ : branches_ - 1;
        p.push_back(make_rung_op(rung_, name, RungOp::Read, at));
    }

    void coil(const Statement& s, std::string_view name, engine::Program& p) {
        // OUT T0 K20 / OUT C1 K10: a timer or counter, as the FX family writes them.
        if (s.spelling.step == Step::Out && !s.operands.empty() && s.named.empty()) {
            const auto d = base_.naming.parse_device(s.operands.front().text);
            const bool timer_or_counter = d && (d->area == Area::T || d->area == Area::C);
            if (timer_or_counter && s.operands.size() == 1) {
                // In the dialect's own words: TMR T0 K10 where it has TMR, else OUT T0 K10.
                const char* word = d->area == Area::T ? "TMR" : "CTR";
                const bool own = dialect_.words.contains(word);
                fail(s, s.operands.front().text + " needs its preset (" + (own ? word : "OUT") +
                            " " + s.operands.front().text + " K10)");
            }
            if (timer_or_counter && s.operands.size() == 2) {
                output(s);
                const bool timer = d->area == Area::T;
                p.push_back(timer ? make_tmr(preset_entry(s, "t"), context())
                                  : make_cnt(preset_entry(s, "c"), context()));
                return;
            }
        }
        if (s.spelling.step == Step::Out && s.operands.size() == 1 && s.named.empty()) {
            if (const auto tr = temporary(s, s.operands.front())) {
                need_rung(s);
                p.push_back(make_rung_op(rung_, "OUT", RungOp::Save, *tr));
                return;
            }
        }
        output(s);
        const Entry e = entry_of(s, {"d"});
        const BindContext ctx = context();
        Operands ops(e, ctx);
        const image::Device d = ops.bit_output("d");
        ops.finish();
        if (s.spelling.step != Step::Set) {
            const auto key = std::make_pair(static_cast<int>(d.area), d.index);
            const auto [it, fresh] = coils_.emplace(key, s.where);
            if (!fresh && warnings_ != nullptr && ++double_coils_ <= kMaxListingWarnings) {
                warnings_->push_back({s.where, s.mnemonic + ": double coil: " +
                                                   image::excerpt(e.operands[0].second.text) +
                                                   " is driven at " + it->second.text() +
                                                   " too; the last one in the scan wins"});
            }
        }
        const CoilOp op = s.spelling.step == Step::Set
                              ? (s.spelling.pulse ? CoilOp::SetOnRising : CoilOp::Set)
                          : s.spelling.step == Step::OutNot ? CoilOp::OutNot
                                                            : CoilOp::Out;
        p.push_back(make_coil(rung_, name, op, d));
    }

    // TMR T0 100 / OUT T0 K20: the device and its preset, for TMR and CNT.
    Entry preset_entry(const Statement& s, const char* device_key) const {
        Statement copy = s;
        // FATEK writes the preset `PV: 100`.
        for (const auto& [k, v] : s.named) {
            if (k == "pv" && copy.operands.size() == 1) {
                copy.operands.push_back(v);
                copy.named.clear();
            }
        }
        Entry e = entry_of(copy, {device_key, "k"});
        return e;
    }

    void master_control(const Statement& s, engine::Program& p) {
        output(s);
        const Entry e = entry_of(s, {"n", "d"});
        const int level = nesting(s, e.operands[0].second);
        if (!levels_.empty() && level <= levels_.back()) {
            throw BindError(e.operands[0].second.where,
                            "MC: N" + std::to_string(level) + " inside N" +
                                std::to_string(levels_.back()) +
                                ": nested levels count up (N0, then N1 …)");
        }
        const Entry coil_entry{s.mnemonic, s.where, {e.operands[1]}, s.step, true};
        const BindContext ctx = context();
        Operands ops(coil_entry, ctx);
        const image::Device coil = ops.bit_output("d");
        ops.finish();
        const int slot = static_cast<int>(levels_.size());
        levels_.push_back(level);
        level_where_.push_back(s.where);
        p.push_back(make_master_control(rung_, slot, coil));
    }

    void master_reset(const Statement& s, engine::Program& p) {
        const Entry e = entry_of(s, {"n"});
        const int level = nesting(s, e.operands[0].second);
        int slot = -1;
        for (std::size_t i = 0; i < levels_.size(); ++i) {
            if (levels_[i] == level) slot = static_cast<int>(i);
        }
        if (slot < 0) {
            throw BindError(e.operands[0].second.where,
                            "MCR: no MC N" + std::to_string(level) + " is open");
        }
        levels_.resize(static_cast<std::size_t>(slot));
        level_where_.resize(static_cast<std::size_t>(slot));
        // MCR ends the rung before it; the next contact starts one.
        if (open_ && !after_output_) fail(s, "the rung before has no output");
        open_ = false;
        after_output_ = false;
        p.push_back(make_master_reset(rung_, slot));
    }

    int nesting(const Statement& s, const Operand& op) const {
        const std::string& t = op.text;
        if (t.size() == 2 && (t[0] == 'N' || t[0] == 'n') && t[1] >= '0' &&
            t[1] < '0' + Rung::kLevels) {
            return t[1] - '0';
        }
        throw BindError(op.where, s.mnemonic + ": expected a nesting level N0–N" +
                                      std::to_string(Rung::kLevels - 1) + ", got '" +
                                      image::excerpt(t) + "'");
    }

    void function(const Statement& s, engine::Program& p) {
        output(s);
        const FunctionSpelling& f = *s.function;
        Entry e{std::string(f.name), s.where, {}, s.step, true};
        if (s.operands.size() > f.positional.size()) {
            std::string keys;
            for (const auto k : f.positional)
                keys += std::string(keys.empty() ? "" : " ") + std::string(k);
            throw BindError(s.operands[f.positional.size()].where,
                            s.mnemonic + ": takes " + std::to_string(f.positional.size()) +
                                " operand" + (f.positional.size() == 1 ? "" : "s") +
                                (keys.empty() ? "" : " (" + keys + ")") + " written in order");
        }
        for (std::size_t i = 0; i < s.operands.size(); ++i)
            e.operands.emplace_back(std::string(f.positional[i]), s.operands[i]);
        for (const auto& [k, v] : s.named) {
            if (k == "en") {
                throw BindError(v.where, s.mnemonic + ": EN is the rung's result; leave `en` out");
            }
            for (const auto& [have, w] : e.operands) {
                if (have == k)
                    throw BindError(v.where, s.mnemonic + ": operand '" + k + "' given twice");
            }
            e.operands.emplace_back(k, v);
        }
        if (s.pulse) e.operands.emplace_back("p", Operand{"true", s.where});
        const auto it = table_.find(f.name);
        if (it == table_.end()) {
            throw BindError(s.where, s.mnemonic + ": not an instruction of this profile");
        }
        p.push_back(it->second(e, context()));
    }

    void finish() const {
        if (branches_ > 0) {
            throw BindError(rung_where_, "the rung from here leaves " + std::to_string(branches_) +
                                             " result(s) on the branch stack (MPP takes the "
                                             "last one)");
        }
        if (open_ && !after_output_) {
            throw BindError(rung_where_, "the rung from here has no output");
        }
        if (!levels_.empty()) {
            throw BindError(level_where_.back(),
                            "MC N" + std::to_string(levels_.back()) + " has no MCR");
        }
    }

    const Dialect& dialect_;
    const Table& table_;
    engine::Declarations earlier_;  // what the statements so far declared
    std::size_t declared_ = 0;      // statements whose declarations are in earlier_
    const BindContext base_;
    std::vector<ListingWarning>* warnings_;
    std::shared_ptr<Rung> rung_;
    bool open_ = false;          // a rung is open
    bool after_output_ = false;  // its last statement was an output
    int blocks_ = 0;             // blocks opened by LD and not yet joined
    int branches_ = 0;           // results on the branch stack
    std::vector<int> levels_;    // open MC levels, in order
    std::vector<Where> level_where_;
    Where rung_where_;
    bool ended_ = false;
    Where end_where_;
    std::map<std::pair<int, std::uint32_t>, Where> coils_;  // OUT coils and where first driven
    std::size_t double_coils_ = 0;                          // coils driven again
};

}  // namespace

engine::Program make_listing_program(const std::vector<Statement>& statements,
                                     const Dialect& dialect,
                                     const Table& table,
                                     const image::Layout& layout,
                                     const image::Naming& naming,
                                     const Services& services,
                                     std::vector<ListingWarning>* warnings,
                                     engine::Tags* operands) {
    ListingBuilder b(dialect, table, layout, naming, services, warnings, operands);
    return b.build(statements);
}

}  // namespace plcemu::instructions
