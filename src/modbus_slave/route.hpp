#pragma once
// A Modbus request to the PLCs behind a listener: the listener's unit table says which PLC (or
// simulator unit) has the unit ID, that PLC's dispatcher answers. The one place that applies the
// unknown-unit policy and builds its exception.

#include <array>
#include <cstdint>
#include <span>

#include "plcemu/listener/unit_table.hpp"
#include "plcemu/modbus/dispatcher.hpp"
#include "plcemu/modbus/unit.hpp"

namespace plcemu::modbus_slave {

/// How the request arrived: the unit IDs 0 and 255 mean different things in the two framings.
enum class Addressing : std::uint8_t {
    Tcp,  ///< 0 and 255 name "the device itself" (Modbus TCP implementation guide §4.4.1.2)
    Rtu,  ///< 0 is a broadcast: served by every PLC on the line, answered by none
};

/// The data a request reaches: `count` elements of `table` from `address` (count 0: none).
struct Reach {
    modbus::Table table = modbus::Table::HoldingRegisters;
    std::uint16_t address = 0;
    std::uint16_t count = 0;
};

/// What `pdu` reads or writes: its one range, or for 17h its read range then its write range.
std::array<Reach, 2> reach(std::span<const std::uint8_t> pdu) noexcept;

/// Answers `pdu` (at least its function code) for `unit` into `out`; returns the reply PDU's
/// size, 0 when nothing is to be sent.
std::size_t route(listener::UnitTable& units,
                  Addressing addressing,
                  std::uint8_t unit,
                  std::span<const std::uint8_t> pdu,
                  modbus::PduBuffer out) noexcept;

/// Records in `traffic` that `client` asked `pdu` of a PLC's `unit` (or its simulator unit) and
/// got `reply`: the function, the address and quantity it names, the exception code.
void record(listener::Traffic& traffic,
            const listener::Client& client,
            std::uint8_t unit,
            bool simulator,
            std::span<const std::uint8_t> pdu,
            std::span<const std::uint8_t> reply);

}  // namespace plcemu::modbus_slave
