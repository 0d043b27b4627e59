#pragma once
// A program in a family's instruction list (the mnemonic view of its programming tool): bit
// logic (contacts, blocks, the branch stack, coils, master control) and the function
// instructions of the family's instruction table, each taking its enable from the rung. A
// profile says how its family spells each statement (a Dialect); nothing here names a family
// (docs/program-language.md).

#include <cstddef>
#include <map>
#include <string>
#include <string_view>
#include <vector>

#include "plcemu/engine/engine.hpp"
#include "plcemu/image/layout.hpp"
#include "plcemu/image/naming.hpp"
#include "plcemu/instructions/instructions.hpp"

namespace plcemu::instructions {

/// One line of a listing as written, and where it starts.
struct ListingLine {
    std::string text;  ///< the line, without its end
    Where where;       ///< where its first character stands
};

/// What a statement does.
enum class Step : std::uint8_t {
    Network,        ///< a contact that starts a network (FATEK's ORG)
    Load,           ///< a contact that starts a rung, or a block inside one (LD)
    And,            ///< a contact in series (AND)
    Or,             ///< a contact in parallel (OR)
    AndBlock,       ///< the last two blocks in series (ANB, ANDLD)
    OrBlock,        ///< the last two blocks in parallel (ORB, ORLD)
    Push,           ///< keeps the result on the branch stack (MPS)
    Read,           ///< takes the result from the branch stack, leaving it there (MRD)
    Pop,            ///< takes the result from the branch stack (MPP)
    Invert,         ///< the result inverted (INV, NOT)
    RisingResult,   ///< the result ON for one scan as it turns ON (FATEK's TU on its own)
    FallingResult,  ///< the result ON for one scan as it turns OFF (FATEK's TD on its own)
    Out,           ///< the result to a coil; with a T or C operand and a preset, a timer or counter
    OutNot,        ///< the inverted result to a coil (FATEK's OUT NOT)
    Set,           ///< a coil ON while the result is ON (SET; with `pulse`, as it turns ON)
    Reset,         ///< a coil, timer, counter or register cleared while the result is ON (RST;
                   ///< with `pulse`, as it turns ON)
    PulseRising,   ///< a coil ON for one scan when the result turns ON (PLS)
    PulseFalling,  ///< a coil ON for one scan when the result turns OFF (PLF)
    Timer,         ///< a timer with its preset (FATEK's TMR)
    Counter,       ///< a counter with its preset, counting rising edges (FATEK's CTR)
    MasterControl,  ///< MC Nn coil: the rungs up to MCR Nn run only while the result is ON
    MasterReset,    ///< MCR Nn
    End,            ///< the end of the program (END)
    Nop,            ///< a step that does nothing (NOP)
};

/// How a contact reads its operand.
enum class Contact : std::uint8_t {
    Open,     ///< normally open: the device
    Closed,   ///< normally closed: the device inverted (NOT, I)
    Rising,   ///< ON for one scan when the device turns ON (TU, P)
    Falling,  ///< ON for one scan when the device turns OFF (TD, F)
    Compare,  ///< two words compared (LD=, AND<, OR<> …), signed
};

/// One spelling of a statement: "LD NOT" → {Load, Closed}.
struct Spelling {
    Step step = Step::Load;           ///< what it does
    Contact contact = Contact::Open;  ///< for a contact, how it reads its operand
    std::string_view relation;        ///< for a comparison, "=", "<>", "<", ">", "<=" or ">="
    bool pulse = false;               ///< for SET and RST, the pulse form (FATEK's SET P, RST P)
};

/// A function instruction of the family's instruction table, as its listing writes it.
struct FunctionSpelling {
    std::string_view name;                     ///< its mnemonic, as in the instruction table
    int number = -1;                           ///< FUN n / FNC n (−1: written by name only)
    std::vector<std::string_view> positional;  ///< operand keys, in the order written bare
    bool pulse = false;                        ///< has a pulse form (MOVP: operand `p`)
};

/// How a family writes its instruction list.
struct Dialect {
    std::string_view tool;  ///< whose mnemonic view it is, for messages
    std::map<std::string, Spelling, std::less<>> words;  ///< statement spellings, upper case
    std::string_view function_prefix;  ///< "FUN" or "FNC": a function by its number
    bool box_labels = false;  ///< a function may be written as its ladder box shows it (86.TPCTL)
    std::vector<FunctionSpelling> functions;  ///< the function instructions it knows
    bool networks = false;       ///< a rung starts with Step::Network (ORG); LD starts only blocks
    std::string_view temporary;  ///< a bit area OUT saves the result in and LD reads it back
                                 ///< from (FATEK's TR), as written; empty: none
    int temporaries = 0;         ///< how many of them
};

/// A statement of a listing: the spelling it matched and its operands.
struct Statement {
    std::string mnemonic;  ///< as the dialect spells it, upper case ("LD NOT", "MOV")
    Where where;           ///< where the mnemonic stands
    Spelling spelling;     ///< what it does, when it is not a function
    const FunctionSpelling* function = nullptr;  ///< the function instruction, when it is one
    bool pulse = false;                          ///< the function's pulse form
    std::vector<Operand> operands;               ///< bare operands, in order
    std::vector<std::pair<std::string, Operand>> named;  ///< `key: value` operands
    int step = 0;                                        ///< 1-based position in the program
};

/// The most statements a listing may hold (docs/program-language.md, "Writing a listing").
inline constexpr std::size_t kMaxStatements = 100'000;

/// The most operands a statement may have, bare and named (TPCTL, the most, takes 14): a
/// statement past it is refused at the operand that crosses it.
inline constexpr std::size_t kMaxOperands = 32;

/// The most double-coil warnings a program gets one by one; the rest are counted in one more.
inline constexpr std::size_t kMaxListingWarnings = 10;

/// Reads a listing: one statement per line (blank lines and `;` or `//` comments left out; a
/// leading step number, as --print-program writes, ignored), a function's `key: value`
/// operands on the same line or on lines of their own below it. Throws BindError at the
/// first statement it cannot read, naming the mnemonic.
std::vector<Statement> read_listing(const std::vector<ListingLine>& lines, const Dialect& dialect);

/// A warning about a program that still runs (a coil driven twice, as the vendors' tools warn).
struct ListingWarning {
    Where where;          ///< where
    std::string message;  ///< what
};

/// Builds the program of `statements`: bit logic here, function instructions through `table`,
/// each with its EN taken from the rung. Checks the rung structure (a block not closed, a
/// branch stack pushed without pop, MC levels) and throws BindError at the statement at fault.
/// Warnings go to `warnings` when it is set; device operands are described in `operands`
/// (BindContext::operands).
engine::Program make_listing_program(const std::vector<Statement>& statements,
                                     const Dialect& dialect,
                                     const Table& table,
                                     const image::Layout& layout,
                                     const image::Naming& naming,
                                     const Services& services,
                                     std::vector<ListingWarning>* warnings = nullptr,
                                     engine::Tags* operands = nullptr);

/// The statements as --print-program shows them: one per line, its step number first.
std::string format_listing(const std::vector<Statement>& statements);

}  // namespace plcemu::instructions
