#pragma once
// The bit logic of a listing: the state one rung works on (its result, the blocks LD opened,
// the branch stack, the master-control levels) and the statements that work on it. Every stack
// position is fixed when the program is built (plcemu/instructions/listing.hpp checks the
// structure), so no statement checks a depth while it runs.

#include <array>
#include <cstdint>
#include <memory>

#include "operands.hpp"
#include "relation.hpp"
#include "plcemu/engine/engine.hpp"
#include "plcemu/image/image.hpp"
#include "plcemu/instructions/listing.hpp"

namespace plcemu::instructions {

/// What the statements of one program share.
struct Rung {
    static constexpr int kBlocks = 32;    ///< blocks open at once (LD inside a rung)
    static constexpr int kBranches = 11;  ///< the branch stack's depth (MPS), as on the FX family
    static constexpr int kLevels = 8;     ///< master-control levels (N0–N7)
    static constexpr int kSaved = 64;     ///< temporary relays (FATEK's TR)

    bool result = false;  ///< the rung's result so far: the enable of a function instruction
    bool enabled = true;  ///< false between an MC whose condition is OFF and its MCR
    std::array<bool, kBlocks> blocks{};            ///< results put aside by LD
    std::array<bool, kBranches> branches{};        ///< the branch stack
    std::array<bool, kLevels + 1> levels{{true}};  ///< `enabled` inside each open MC level
    std::array<bool, kSaved> saved{};              ///< temporary relays
};

/// Where a contact's bit comes from and how it is read.
struct ContactSource {
    Contact contact = Contact::Open;   ///< how
    image::Device device;              ///< the device (not a comparison)
    Relation relation = Relation::Eq;  ///< a comparison's
    WordSource s1;                     ///< a comparison's left side
    WordSource s2;                     ///< a comparison's right side
};

/// How a contact combines with the rung.
enum class Join : std::uint8_t {
    Start,  ///< starts the rung
    Block,  ///< puts the result aside (at `depth`) and starts a block
    And,    ///< in series
    Or,     ///< in parallel
};

/// A contact statement (LD, AND, OR and their forms; ORG).
std::unique_ptr<engine::Instruction> make_contact(std::shared_ptr<Rung> rung,
                                                  std::string_view mnemonic,
                                                  Join join,
                                                  int depth,
                                                  const ContactSource& source);

/// What a statement that works on the rung's state alone does.
enum class RungOp : std::uint8_t {
    AndBlock,  ///< result = blocks[depth] AND result
    OrBlock,   ///< result = blocks[depth] OR result
    Push,      ///< branches[depth] = result
    Read,      ///< result = branches[depth]
    Invert,    ///< result = NOT result
    Rising,    ///< result = ON for one scan as it turns ON
    Falling,   ///< result = ON for one scan as it turns OFF
    Save,      ///< saved[depth] = result
    Restore,   ///< result = saved[depth]
};

/// ANB/ORB, MPS/MRD/MPP (a pop is a read: the depth is the builder's), INV, TU/TD on their
/// own, OUT/LD of a temporary relay.
std::unique_ptr<engine::Instruction> make_rung_op(std::shared_ptr<Rung> rung,
                                                  std::string_view mnemonic,
                                                  RungOp op,
                                                  int depth);

/// What a coil does with the rung's result.
enum class CoilOp : std::uint8_t {
    Out,          ///< the device = result
    OutNot,       ///< the device = NOT result
    Set,          ///< ON while the result is ON
    SetOnRising,  ///< ON as the result turns ON (SET P)
};

/// OUT, OUT NOT, SET, SET P on a bit device.
std::unique_ptr<engine::Instruction> make_coil(std::shared_ptr<Rung> rung,
                                               std::string_view mnemonic,
                                               CoilOp op,
                                               image::Device device);

/// MC Nn with its coil: level `slot` (its place among the open levels) opens.
std::unique_ptr<engine::Instruction> make_master_control(std::shared_ptr<Rung> rung,
                                                         int slot,
                                                         image::Device coil);

/// MCR Nn: the level opened at `slot` closes, and every one above it.
std::unique_ptr<engine::Instruction> make_master_reset(std::shared_ptr<Rung> rung, int slot);

}  // namespace plcemu::instructions
