#include "profiles/vb/listing.hpp"

#include <string>
#include <utility>

namespace plcemu::profiles::vb {

namespace {

using instructions::Contact;
using instructions::Spelling;
using instructions::Step;

instructions::Dialect make() {
    instructions::Dialect d;
    d.tool = "the VB instruction list (Ladder Master)";
    // LD/AND/OR with I (normally closed), P (rising) and F (falling); AND's I form is ANI.
    const std::pair<const char*, Step> contacts[] = {
        {"LD", Step::Load}, {"AND", Step::And}, {"OR", Step::Or}};
    for (const auto& [name, step] : contacts) {
        const std::string n = name;
        d.words.emplace(n, Spelling{step, Contact::Open, {}});
        d.words.emplace(n == "AND" ? "ANI" : n + "I", Spelling{step, Contact::Closed, {}});
        d.words.emplace(n + "P", Spelling{step, Contact::Rising, {}});
        d.words.emplace(n + "F", Spelling{step, Contact::Falling, {}});
        // The comparison contacts: LD= S1 S2, AND<> S1 S2, OR>= S1 S2 …
        for (const char* rel : {"=", "<>", "<", ">", "<=", ">="}) {
            d.words.emplace(n + rel, Spelling{step, Contact::Compare, rel});
        }
    }
    d.words.emplace("ANB", Spelling{Step::AndBlock, Contact::Open, {}});
    d.words.emplace("ORB", Spelling{Step::OrBlock, Contact::Open, {}});
    d.words.emplace("MPS", Spelling{Step::Push, Contact::Open, {}});
    d.words.emplace("MRD", Spelling{Step::Read, Contact::Open, {}});
    d.words.emplace("MPP", Spelling{Step::Pop, Contact::Open, {}});
    d.words.emplace("INV", Spelling{Step::Invert, Contact::Open, {}});
    d.words.emplace("OUT", Spelling{Step::Out, Contact::Open, {}});
    d.words.emplace("SET", Spelling{Step::Set, Contact::Open, {}});
    d.words.emplace("RST", Spelling{Step::Reset, Contact::Open, {}});
    d.words.emplace("PLS", Spelling{Step::PulseRising, Contact::Open, {}});
    d.words.emplace("PLF", Spelling{Step::PulseFalling, Contact::Open, {}});
    d.words.emplace("MC", Spelling{Step::MasterControl, Contact::Open, {}});
    d.words.emplace("MCR", Spelling{Step::MasterReset, Contact::Open, {}});
    d.words.emplace("END", Spelling{Step::End, Contact::Open, {}});
    d.words.emplace("NOP", Spelling{Step::Nop, Contact::Open, {}});
    d.function_prefix = "FNC";
    // FNC numbers as the FX family and the VB manual number them (FNC88 PID, FNC92 TPID,
    // FNC149 MBUS, FNC169 HOUR); operands in the order the manuals write them.
    d.functions = {
        {"CMP", 10, {"s1", "s2", "d"}, true},
        {"MOV", 12, {"s", "d"}, true},
        {"WOR", 27, {"s1", "s2", "d"}, false},
        {"ZRST", 40, {"d1", "d2"}, true},
        {"FROM", 78, {"m1", "m2", "d", "n"}, true},
        {"TO", 79, {"m1", "m2", "s", "n"}, true},
        {"PID", 88, {"s1", "s2", "s3", "d"}, false},
        {"TPID", 92, {"s1", "s2", "s3", "s4", "n"}, false},
        {"MBUS", 149, {"s1", "s2"}, false},
        {"HOUR", 169, {"s", "d1", "d2"}, false},
        {"DHOUR", -1, {"s", "d1", "d2"}, false},
    };
    return d;
}

}  // namespace

const instructions::Dialect& listing_dialect() {
    static const instructions::Dialect kDialect = make();
    return kDialect;
}

}  // namespace plcemu::profiles::vb
