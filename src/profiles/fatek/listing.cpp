#include "profiles/fatek/listing.hpp"

#include <chrono>
#include <string>
#include <utility>

namespace plcemu::profiles::fatek {

using instructions::Contact;
using instructions::Spelling;
using instructions::Step;

instructions::Dialect listing_dialect(std::vector<instructions::FunctionSpelling> functions) {
    instructions::Dialect d;
    d.tool = "WinProladder's mnemonic view";
    // A network starts with ORG; LD starts a block inside it, joined by ANDLD or ORLD. Each
    // contact has its NOT (normally closed), TU (rising) and TD (falling) forms.
    const std::pair<const char*, Step> contacts[] = {
        {"ORG", Step::Network}, {"LD", Step::Load}, {"AND", Step::And}, {"OR", Step::Or}};
    const std::pair<const char*, Contact> forms[] = {{"", Contact::Open},
                                                     {" NOT", Contact::Closed},
                                                     {" TU", Contact::Rising},
                                                     {" TD", Contact::Falling}};
    for (const auto& [name, step] : contacts) {
        for (const auto& [suffix, contact] : forms) {
            d.words.emplace(std::string(name) + suffix, Spelling{step, contact, {}});
        }
    }
    d.words.emplace("ANDLD", Spelling{Step::AndBlock, Contact::Open, {}});
    d.words.emplace("ORLD", Spelling{Step::OrBlock, Contact::Open, {}});
    d.words.emplace("NOT", Spelling{Step::Invert, Contact::Open, {}});
    // TU and TD on their own: the differential of the rung's result so far.
    d.words.emplace("TU", Spelling{Step::RisingResult, Contact::Open, {}});
    d.words.emplace("TD", Spelling{Step::FallingResult, Contact::Open, {}});
    d.words.emplace("OUT", Spelling{Step::Out, Contact::Open, {}});
    d.words.emplace("OUT NOT", Spelling{Step::OutNot, Contact::Open, {}});
    d.words.emplace("SET", Spelling{Step::Set, Contact::Open, {}});
    d.words.emplace("RST", Spelling{Step::Reset, Contact::Open, {}});
    // The pulse forms: each acts once, as the result turns ON.
    d.words.emplace("SET P", Spelling{Step::Set, Contact::Open, {}, true});
    d.words.emplace("RST P", Spelling{Step::Reset, Contact::Open, {}, true});
    d.words.emplace("TMR", Spelling{Step::Timer, Contact::Open, {}});
    d.words.emplace("CTR", Spelling{Step::Counter, Contact::Open, {}});
    d.words.emplace("END", Spelling{Step::End, Contact::Open, {}});
    d.function_prefix = "FUN";
    d.box_labels = true;
    d.functions = std::move(functions);
    d.networks = true;
    // TR0–TR39: OUT TRn keeps the node's state at a branch, LD TRn takes it back.
    d.temporary = "TR";
    d.temporaries = 40;
    return d;
}

std::vector<instructions::TimerGroup> timer_groups() {
    using std::chrono::milliseconds;
    return {{0, 50, milliseconds(10), false},
            {50, 150, milliseconds(100), false},
            {200, 56, milliseconds(1000), false}};
}

}  // namespace plcemu::profiles::fatek
