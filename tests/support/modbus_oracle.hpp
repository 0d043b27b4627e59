#pragma once
// Test support: libmodbus as the reference the PLC's Modbus codec is held to (docs/testing.md,
// "Where the PLC differs from libmodbus on purpose"). Every request served through the oracle
// is answered by the PLC's dispatcher and by libmodbus' modbus_reply() on a modbus_mapping_t
// holding the same values as the window of the image the request touches; the two replies must
// be identical byte for byte, and a write must land identically. The PLC's map decides what an
// address means (a gap, a read-only or write-protected range refuses the window: libmodbus gets
// no mapping there and must refuse too); each class of request where the PLC differs from
// libmodbus on purpose is counted under its own name and not compared.

#include <array>
#include <cstddef>
#include <cstdint>
#include <span>
#include <string>

#include "modbus_slave/rtu.hpp"
#include "modbus_slave/tcp.hpp"
#include "plcemu/modbus/dispatcher.hpp"
#include "plcemu/modbus/unit.hpp"

struct _modbus;
struct _modbus_mapping_t;

namespace plcemu::testing {

/// The framing a request arrived in.
enum class Framing : std::uint8_t { Tcp, Rtu };

/// How a request went through the oracle: compared, or why not.
enum class OracleCase : std::uint8_t {
    Compared,             ///< both answered from the same values; replies and writes equal
    ComparedRefused,      ///< the PLC's map refused the window; libmodbus, given none, refused too
    NotThePlc,            ///< a unit the PLC does not answer as (routing is not libmodbus' part)
    SimulatorUnit,        ///< the simulator-control unit (its writes run scans)
    Identity,             ///< FC 08, 11h, 2Bh: the PLC's own identity and diagnostics
    ReadExceptionStatus,  ///< FC 07: libmodbus 3.1.6 sends nothing at all
    FunctionAbove7F,      ///< libmodbus adds 80h and wraps; the PLC sets the high bit
    ProtocolId,           ///< MBAP protocol ID not 0: the TCP transport closes the connection
    LengthNotFramed,      ///< a PDU length libmodbus would not have framed: the PLC answers 03
    TableNotServed,       ///< a table the unit does not serve: the PLC answers 01
    ProfileFunction,      ///< a code the profile adds, or one libmodbus serves that it refuses
    Fc05ValueFirst,       ///< FC 05, bad value at a refused address: 03 first, as the protocol says
    Fc0FByteCount,        ///< FC 0Fh byte count above ceil(quantity / 8): the PLC answers 03
    BroadcastFc17,        ///< FC 17h broadcast: the PLC ignores it (it reads), libmodbus writes
    AliasedWindow,        ///< a request's window reaches the same device twice
};

/// Number of OracleCase values.
inline constexpr std::size_t kOracleCases = 15;

/// The PLC's side of the comparison: the Modbus protocols of a listener of its own (its one
/// seat), as the daemon serves it.
struct PlcSide {
    modbus_slave::ModbusTcp& tcp;  ///< Modbus TCP
    modbus_slave::ModbusRtu& rtu;  ///< Modbus RTU
};

/// The oracle. One per process (the libmodbus contexts and their socket pair are made once).
class ModbusOracle {
public:
    /// The process's oracle.
    static ModbusOracle& get();

    /// What serve() did.
    struct Result {
        std::size_t size = 0;                   ///< bytes of the PLC's reply in `out`
        OracleCase how = OracleCase::Compared;  ///< compared, or why not
        std::string mismatch;                   ///< empty unless the PLC and libmodbus differ
    };

    /// Serves `adu` (a TCP ADU or an RTU frame with its CRC) on `plc` (the protocols of a PLC
    /// whose unit is `unit`), its reply into `out`, and on libmodbus, and compares.
    Result serve(PlcSide plc,
                 modbus::Unit& unit,
                 Framing framing,
                 std::span<const std::uint8_t> adu,
                 std::span<std::uint8_t> out);

    /// Requests counted under `c`.
    std::uint64_t count(OracleCase c) const { return counts_[static_cast<std::size_t>(c)]; }
    /// One line per case with a count: its name, the count and why.
    std::string summary() const;
    /// The name of `c`, e.g. "identity".
    static const char* name(OracleCase c);
    /// Why `c` is not compared (or how it is).
    static const char* why(OracleCase c);

    ModbusOracle(const ModbusOracle&) = delete;
    ModbusOracle& operator=(const ModbusOracle&) = delete;

private:
    ModbusOracle();

    _modbus* tcp_ = nullptr;
    _modbus* rtu_ = nullptr;
    _modbus_mapping_t* map_ = nullptr;
    int ours_ = -1;    // the contexts' end of the socket pair
    int theirs_ = -1;  // where their replies are read
    std::array<std::uint64_t, kOracleCases> counts_{};
};

}  // namespace plcemu::testing
