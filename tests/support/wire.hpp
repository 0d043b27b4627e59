#pragma once
// Test support: drives the Modbus TCP and RTU protocols of a listener the way the listeners do
// (one PLC on a listener of its own, or several sharing one), and returns the reply bytes.

#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "modbus_slave/rtu.hpp"
#include "modbus_slave/tcp.hpp"
#include "plcemu/daemon/plc.hpp"
#include "plcemu/modbus/dispatcher.hpp"

namespace plcemu::testing {

/// Sends requests to a dispatcher and reads what it writes back.
class Wire {
public:
    /// One PLC on a listener of its own: `station` is read on every request, `sim` (when given)
    /// answers `sim_unit`. Everything given must outlive the wire. Every request also goes to
    /// libmodbus beside the PLC: every reply and every write must be libmodbus' too, where
    /// comparable (support/modbus_oracle.hpp); a difference throws.
    Wire(modbus::Dispatcher& d,
         modbus::Unit& unit,
         const std::uint8_t& station,
         modbus::Unit* sim = nullptr,
         std::uint8_t sim_unit = 0);
    /// A built PLC on a listener of its own, with the oracle as above.
    explicit Wire(daemon::Plc& plc);
    /// Several PLCs sharing a listener (no oracle: routing is not libmodbus' part).
    explicit Wire(std::vector<listener::Seat> seats);

    /// Sets the policy for unit IDs nobody has.
    void set_unknown_unit(listener::UnknownUnit u);
    /// The TCP side's unit table.
    listener::UnitTable& tcp_units() { return tcp_.units(); }
    /// The RTU side's unit table.
    listener::UnitTable& rtu_units() { return rtu_.units(); }

    /// Serves a TCP request with unit `unit` and PDU `pdu`; returns the reply PDU (without
    /// MBAP), empty when nothing was sent. Checks the MBAP header of the reply.
    std::vector<std::uint8_t> tcp(std::uint8_t unit, const std::vector<std::uint8_t>& pdu);
    /// Serves an RTU frame (address, PDU, CRC added here); returns the reply PDU (without
    /// address and CRC, both checked), empty when nothing was sent.
    std::vector<std::uint8_t> rtu(std::uint8_t unit, const std::vector<std::uint8_t>& pdu);

private:
    std::vector<std::uint8_t> reply(std::size_t n) const;
    std::size_t serve(bool tcp, const std::vector<std::uint8_t>& adu);

    modbus_slave::ModbusTcp tcp_;
    modbus_slave::ModbusRtu rtu_;
    bool oracle_ = false;
    std::array<std::uint8_t, 260> out_{};
    std::uint16_t tid_ = 0x1234;
};

/// PDU builders.
std::vector<std::uint8_t> read_pdu(std::uint8_t fc, std::uint16_t addr, std::uint16_t qty);
std::vector<std::uint8_t> write_single_pdu(std::uint8_t fc, std::uint16_t addr, std::uint16_t v);
std::vector<std::uint8_t> write_registers_pdu(std::uint16_t addr,
                                              const std::vector<std::uint16_t>& values);
std::vector<std::uint8_t> write_coils_pdu(std::uint16_t addr, const std::vector<bool>& values);
/// Words of a FC03/04 reply PDU.
std::vector<std::uint16_t> reply_words(const std::vector<std::uint8_t>& pdu);
/// Bits of a FC01/02 reply PDU.
std::vector<bool> reply_bits(const std::vector<std::uint8_t>& pdu, std::size_t qty);
/// The exception code of a reply, or 0 when it is not an exception.
std::uint8_t exception_of(const std::vector<std::uint8_t>& pdu);

}  // namespace plcemu::testing
