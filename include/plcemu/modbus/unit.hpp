#pragma once
// A Modbus unit: something that turns wire addresses into memory the protocol code may read or
// write in place, or into a refusal.

#include <cstddef>
#include <cstdint>
#include <optional>

#include "plcemu/image/area.hpp"

namespace plcemu::modbus {

/// The four Modbus data tables.
enum class Table : std::uint8_t { Coils, DiscreteInputs, HoldingRegisters, InputRegisters };

/// Modbus exception codes, and Ok.
enum class Status : std::uint8_t {
    Ok = 0,
    IllegalFunction = 0x01,
    IllegalDataAddress = 0x02,
    IllegalDataValue = 0x03,
    ServerFailure = 0x04,
    GatewayTargetFailed = 0x0B,
};

/// The memory a request reads or writes: `bits`/`words` point at the element for the request's
/// first wire address, followed by the rest of the request's elements.
struct Window {
    Status status = Status::IllegalDataAddress;  ///< Ok, or why not
    std::uint8_t* bits = nullptr;                ///< coils / discrete inputs, one byte each
    std::uint16_t* words = nullptr;              ///< holding / input registers
    /// Registers over bits: register i is bits[16i] (b0) … bits[16i+15] (b15), and `words` is
    /// null (a map row of packed bits such as WM0).
    bool packed = false;
    /// Elements the window covers from the request's first address; 0: all of them. A request
    /// that runs across two map rows whose devices do not continue each other (D7999, D9000) is
    /// served as consecutive windows (see resolve_span).
    std::uint16_t count = 0;

    /// Register `i` of a register window.
    std::uint16_t word(std::size_t i) const {
        if (!packed) return words[i];
        unsigned v = 0;
        for (unsigned b = 0; b < 16; ++b) v |= (bits[16 * i + b] != 0 ? 1u : 0u) << b;
        return static_cast<std::uint16_t>(v);
    }
    /// Writes register `i` of a register window.
    void set_word(std::size_t i, std::uint16_t v) const {
        if (!packed) {
            words[i] = v;
            return;
        }
        for (unsigned b = 0; b < 16; ++b)
            bits[16 * i + b] = static_cast<std::uint8_t>((v >> b) & 1u);
    }
};

/// One addressable unit (the PLC itself, the simulator-control unit, …).
class Unit {
public:
    virtual ~Unit() = default;
    /// Resolves `qty` elements of `table` from wire address `addr`, for reading or writing.
    /// Returns IllegalFunction when the table is not served, IllegalDataAddress when any element
    /// is unmapped or (for writes) read-only.
    virtual Window resolve(Table table,
                           std::uint16_t addr,
                           std::uint16_t qty,
                           bool write) noexcept = 0;
    /// Whether the unit answers function code `fc` at all (the dispatcher refuses the rest with
    /// IllegalFunction before any handler runs): a PLC answers every one the dispatcher has.
    virtual bool serves(std::uint8_t /*fc*/) const noexcept { return true; }
    /// Called after a write landed in a window this unit returned.
    virtual void written(Table /*table*/, std::uint16_t /*addr*/, std::uint16_t /*qty*/) noexcept {}
    /// The devices `qty` elements of `table` from `addr` reach, as far as one range goes (the
    /// console's traffic page names them); nothing for a unit without devices or an address
    /// its map lacks.
    virtual std::optional<image::Range> devices(Table /*table*/,
                                                std::uint16_t /*addr*/,
                                                std::uint16_t /*qty*/) const noexcept {
        return std::nullopt;
    }
};

}  // namespace plcemu::modbus
