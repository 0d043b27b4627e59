#pragma once
// Where a VB instruction reports an operation error: D9067 takes the code, M9067 comes ON and
// D9069 names the program entry (VB manual FNC88, error codes 6730–6750 "in D9067"). Both stay
// until a master or the program clears them, or the next start (docs/profile-vb.md, "Special
// relays and registers").

#include <cstdint>

#include "plcemu/image/image.hpp"
#include "plcemu/instructions/instructions.hpp"
#include "profiles/vb/specials.hpp"

namespace plcemu::profiles::vb {

/// Codes more than one instruction stores.
enum ErrorCode : std::uint16_t {
    /// An operand outside its range (FX's 670x operand-error class; the VB manual lists no code
    /// for FROM/TO or TPID: docs/profile-vb.md).
    kOperandError = 6705,
    /// Auto-tuning could not start or measured no PV swing (FX3U's code; VB manual FNC88 and
    /// FNC92 auto-tuning, which list none).
    kTuningFault = 6750,
};

/// D9067, M9067, D9069.
inline const instructions::OperationError kOperationError{
    {image::Area::D, special::kErrorCode, false},
    {image::Area::M, special::kOperationError, false},
    {image::Area::D, special::kErrorEntry, false},
    kOperandError};

/// Stores `code` for the program entry `entry` (1-based).
inline void raise_operation_error(image::Image& img, std::uint16_t code, int entry) noexcept {
    kOperationError.raise(img, code, entry);
}

}  // namespace plcemu::profiles::vb
