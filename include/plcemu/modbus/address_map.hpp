#pragma once
// A Modbus address map as data: wire ranges → device ranges. A profile has a default map; a
// config's `modbus.map` replaces it with rows of its own.

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "plcemu/image/area.hpp"
#include "plcemu/image/image.hpp"
#include "plcemu/modbus/unit.hpp"

namespace plcemu::modbus {

/// One row of a map.
struct MapRow {
    Table table;               ///< the Modbus table
    std::uint16_t wire_start;  ///< first wire address (the manual's number minus 1)
    std::uint16_t count;       ///< elements (registers for a packed row)
    image::Range devices;      ///< device range it maps to (bits for a packed row: 16 × count)
    std::string codes;         ///< function codes that reach it, as the manual lists them
    std::string label;         ///< the family's name of the range, e.g. "C200-C255 (32-bit)"
    bool packed = false;       ///< registers over 16 bits each (WM0: M0–M15 in one register)
    bool read_only = false;    ///< writes get exception 02
};

/// A device range resolved from a request, or the exception that refuses it.
struct Resolution {
    Status status = Status::IllegalDataAddress;  ///< Ok or the refusal
    image::Range devices;                        ///< valid when Ok
    bool packed = false;                         ///< registers over 16 bits each
    /// Wire elements `devices` covers from the first address (0: all of them); fewer than asked
    /// when the next address belongs to a row whose devices do not continue these (resolve the
    /// rest then).
    std::uint16_t elements = 0;
};

/// The map of one PLC. Resolution reads the image because a family may keep maps there.
class AddressMap {
public:
    virtual ~AddressMap() = default;
    /// The fixed table, for --print-map and tests.
    virtual const std::vector<MapRow>& rows() const = 0;
    /// Lines describing the maps that depend on the image, for --print-map.
    virtual std::vector<std::string> dynamic_notes() const = 0;
    /// Resolves a request to one contiguous device range.
    virtual Resolution resolve(const image::Image& image,
                               Table table,
                               std::uint16_t addr,
                               std::uint16_t qty) const noexcept = 0;
    /// Device ranges that no Modbus write may change (inputs, read-only specials).
    virtual const std::vector<image::Range>& read_only() const = 0;
};

/// The function codes that reach a table, as the manuals list them ("03 06 16 22 23").
const char* function_codes(Table table);

/// Resolves a request against `rows`, as far as one contiguous device range goes: across rows
/// that continue the same range (C199, C200 values), and stopping where the next row maps
/// other devices (D7999 at 7999, D9000 at 8000), with `elements` saying how far it got. An
/// address no row maps, or a device the image lacks, is exception 02.
Resolution resolve_rows(const std::vector<MapRow>& rows,
                        const image::Image& image,
                        Table table,
                        std::uint16_t addr,
                        std::uint16_t qty) noexcept;

/// A map that is only its rows (a family's default table, or a config's `modbus.map`).
/// `read_only` adds device ranges to the rows marked read-only.
std::unique_ptr<AddressMap> make_table_map(std::vector<MapRow> rows,
                                           std::vector<image::Range> read_only);

}  // namespace plcemu::modbus
