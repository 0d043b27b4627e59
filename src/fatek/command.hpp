#pragma once
// The FATEK commands (FBs manual, Appendix 2 FATEK Communication Protocol; docs/profile-fbs.md,
// "FATEK protocol"): one handler per command code, each seeing only the request's data, the PLC
// and the reply to write. A handler checks everything before it changes anything, in the order
// format (4), value (2), address (A), write protection (3), so that a refused request changes
// nothing.

#include <array>
#include <cstdint>
#include <optional>
#include <span>
#include <vector>

#include "error.hpp"
#include "hex.hpp"
#include "plcemu/engine/engine.hpp"
#include "plcemu/image/image.hpp"
#include "reply.hpp"

namespace plcemu::fatek {

/// The PLC a request is for.
struct Target {
    engine::Engine& engine;  ///< its image, RUN/STOP and disabled discretes
    /// Devices no master may write (null: none).
    const std::vector<image::Range>* protected_ranges = nullptr;
    bool read_only = false;  ///< the listener changes nothing: every write is error 3
};

/// A command: checks and executes `data`, writing the reply's data after its error code; returns
/// the error code (None: the reply's data are complete; otherwise they are dropped).
using Handler = Error (*)(std::span<const std::uint8_t> data, Target& plc, Reply& reply) noexcept;

/// A row of the command table.
struct Command {
    Handler handler = nullptr;  ///< null: no such command (error 4)
    bool error_code = true;     ///< false for 4E, whose reply is the request's data alone
};

/// The commands by code.
using CommandTable = std::array<Command, 256>;
/// The table of every command the emulator answers.
const CommandTable& commands() noexcept;

/// The count `NN` at the start of `data` (2 hex digits), or nothing (error 4).
inline std::optional<std::uint32_t> read_count(std::span<const std::uint8_t> data) noexcept {
    if (data.size() < 2) return std::nullopt;
    return parse_hex(data.first(2));
}

namespace handlers {
Error gist_status(std::span<const std::uint8_t>, Target&, Reply&) noexcept;         // 40
Error run_stop(std::span<const std::uint8_t>, Target&, Reply&) noexcept;            // 41
Error discrete_control(std::span<const std::uint8_t>, Target&, Reply&) noexcept;    // 42
Error read_disable_flags(std::span<const std::uint8_t>, Target&, Reply&) noexcept;  // 43
Error read_discretes(std::span<const std::uint8_t>, Target&, Reply&) noexcept;      // 44
Error write_discretes(std::span<const std::uint8_t>, Target&, Reply&) noexcept;     // 45
Error read_registers(std::span<const std::uint8_t>, Target&, Reply&) noexcept;      // 46
Error write_registers(std::span<const std::uint8_t>, Target&, Reply&) noexcept;     // 47
Error mixed_read(std::span<const std::uint8_t>, Target&, Reply&) noexcept;          // 48
Error mixed_write(std::span<const std::uint8_t>, Target&, Reply&) noexcept;         // 49
Error loop_back(std::span<const std::uint8_t>, Target&, Reply&) noexcept;           // 4E
Error detailed_status(std::span<const std::uint8_t>, Target&, Reply&) noexcept;     // 53
}  // namespace handlers

}  // namespace plcemu::fatek
