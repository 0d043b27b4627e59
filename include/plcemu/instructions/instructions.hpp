#pragma once
// Building program instructions from program entries: an instruction table maps mnemonics to
// builders (each profile has its own), and a builder gets its entry's operands and the services
// it needs. The daemon turns the config's `program:` into entries; nothing here reads a config.

#include <functional>
#include <map>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "plcemu/engine/engine.hpp"
#include "plcemu/image/image.hpp"
#include "plcemu/image/layout.hpp"
#include "plcemu/image/naming.hpp"

namespace plcemu::instructions {

/// Where a program entry or an operand stands in the file it was written in.
struct Where {
    std::string file;  ///< file name as given
    int line = 0;      ///< 1-based line
    int column = 0;    ///< 1-based column

    /// "file:line:col".
    std::string text() const;
};

/// An operand as written ("R100", "K10"), and where.
struct Operand {
    std::string text;  ///< the scalar as written
    Where where;       ///< where it stands
};

/// One program entry, e.g. `TPCTL: {en: M0, ...}`.
struct Entry {
    std::string mnemonic;                                   ///< "MOV", "TPCTL", …
    Where where;                                            ///< where the mnemonic stands
    std::vector<std::pair<std::string, Operand>> operands;  ///< in the order written
    int index = 0;  ///< 1-based position in the program (a PLC's step number stands for it)
    /// Whether `index` is a listing's step number rather than the place among YAML entries.
    bool step = false;

    /// How the program names this entry: "program entry 3", or "step 3" in a listing.
    std::string ordinal() const;
};

/// An entry that cannot be built: the message, and where the fault is (the daemon reports it
/// as a configuration error at that line and column).
class BindError : public std::runtime_error {
public:
    BindError(Where where, const std::string& message);
    /// Where the fault is.
    const Where& where() const { return where_; }

private:
    Where where_;
};

/// Where a family reports an instruction's operation error: a code register, a flag relay and a
/// register naming the program entry (the VB's D9067, M9067, D9069).
struct OperationError {
    image::Device code;               ///< takes the error code
    image::Device flag;               ///< comes ON
    image::Device entry;              ///< takes the entry's 1-based position
    std::uint16_t operand_error = 0;  ///< the family's code for an operand out of its range

    /// Reports `code` for the program entry `index`.
    void raise(image::Image& img, std::uint16_t error, int index) const noexcept;
};

/// What a profile offers its instructions while they bind. A profile with more to offer derives
/// from it (its own instructions know the derived type).
struct Services {
    virtual ~Services() = default;
    /// Outputs the program may not drive, each with the reason an error gives.
    std::vector<std::pair<image::Range, std::string>> reserved_outputs;
    /// Where operation errors go; absent: the family has no such register and they go unseen.
    std::optional<OperationError> operation_error;
};

/// What an instruction may look at while it binds its operands.
struct BindContext {
    const image::Layout& layout;          ///< device limits
    const image::Naming& naming;          ///< how devices and constants are written
    const Services& services;             ///< the profile's services
    const engine::Declarations& earlier;  ///< what the entries bound before this one declared
    /// When set, every device operand that binds is added here with the entry's mnemonic, the
    /// operand's key and its position (the tag export); null while a PLC is built to run.
    engine::Tags* operands = nullptr;
    /// In a program written as a listing, the result of the rung an instruction stands on: its
    /// enable (`en`) is that result (plcemu/instructions/listing.hpp); null otherwise.
    const bool* rung = nullptr;
};

/// Builds one instruction; throws BindError (at the operand's position).
using Builder = std::unique_ptr<engine::Instruction> (*)(const Entry&, const BindContext&);
/// Mnemonic → builder.
using Table = std::map<std::string, Builder, std::less<>>;

/// Builds the whole program with `table`; an unknown mnemonic is an error naming the ones the
/// table knows. With `operands`, the device operands are described there
/// (BindContext::operands).
engine::Program make_program(const std::vector<Entry>& program,
                             const Table& table,
                             const image::Layout& layout,
                             const image::Naming& naming,
                             const Services& services,
                             engine::Tags* operands = nullptr);

}  // namespace plcemu::instructions
