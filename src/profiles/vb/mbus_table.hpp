#pragma once
// One transfer set of the FNC149 MBUS communication table, checked and turned into a Modbus
// request (VB manual FNC149, "The register headed with S1"; docs/profile-vb.md, "FNC149 MBUS").

#include <array>
#include <cstdint>
#include <span>

#include "plcemu/image/area.hpp"
#include "plcemu/image/layout.hpp"
#include "plcemu/image/naming.hpp"

namespace plcemu::profiles::vb::mbus {

/// Words of one transfer set: station, command, length, master type, master number, slave
/// type, slave number.
inline constexpr std::uint32_t kSetWords = 7;

/// Status codes of S2+0's high byte, in the manual's order.
enum Status : std::uint8_t {
    kNormal = 0,        ///< the transfer succeeded
    kLengthError = 1,   ///< length not 1–64
    kTypeError = 2,     ///< device type (or command) error
    kNumberError = 3,   ///< device number (or station, or table) error
    kKindMismatch = 4,  ///< master and slave device kinds differ (bit vs word)
    kNoResponse = 5,    ///< "normal communications but no response": time-out
    kAbnormal = 6,      ///< abnormal communications: exception or malformed reply
};

/// A set that passed the checks: what to send and where its data live in the master.
struct Transfer {
    std::uint8_t station = 0;   ///< slave station
    bool read = true;           ///< command 1 (else a write, command 2 or 3)
    std::uint8_t function = 0;  ///< Modbus function code
    std::uint16_t address = 0;  ///< slave start (wire address)
    std::uint16_t count = 0;    ///< bits or registers
    image::Range master;        ///< the master devices
};

/// The outcome of checking one set: `status` kNormal and the transfer, or the status to report.
struct Checked {
    Status status = kNormal;  ///< kNormal, or why the set is skipped
    Transfer transfer;        ///< valid when status is kNormal
};

/// Checks `set` in the manual's order (station, command, length, types, writes to read-only
/// slave types, bit/word kinds, numbers); `layout` says which master devices exist, `naming`
/// which areas are numbered in octal and which counters have 32-bit values. A read whose master
/// devices overlap `read_only` (the file registers: program data the program only reads) is a
/// device number error too; a write may send them.
Checked check_set(const std::array<std::uint16_t, kSetWords>& set,
                  const image::Layout& layout,
                  const image::Naming& naming,
                  std::span<const image::Range> read_only = {});

}  // namespace plcemu::profiles::vb::mbus
