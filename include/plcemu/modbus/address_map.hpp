#pragma once
// A profile's Modbus address map as data: wire ranges → device ranges.

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "plcemu/image/area.hpp"
#include "plcemu/image/image.hpp"
#include "plcemu/modbus/unit.hpp"

namespace plcemu::modbus {

/// One row of a manual's Modbus table.
struct MapRow {
    Table table;               ///< coils or holding registers
    std::uint16_t wire_start;  ///< first wire address (manual number minus 1)
    std::uint16_t count;       ///< elements
    image::Range devices;      ///< device range it maps to
    const char* codes;         ///< function codes, as the manual lists them
    const char* label;  ///< FATEK name of the range, e.g. "C200-C255 (32-bit, low word first)"
};

/// A device range resolved from a request, or the exception that refuses it.
struct Resolution {
    Status status = Status::IllegalDataAddress;  ///< Ok or the refusal
    image::Range devices;                        ///< valid when Ok
};

/// The map of one profile. Resolution reads the image because FATEK's user remap lives there.
class AddressMap {
public:
    virtual ~AddressMap() = default;
    /// The fixed table, for --print-map and tests.
    virtual const std::vector<MapRow>& rows() const = 0;
    /// Lines describing the maps that depend on the image (FATEK's user remap), for --print-map.
    virtual std::vector<std::string> dynamic_notes() const = 0;
    /// Resolves a request to one contiguous device range.
    virtual Resolution resolve(const image::Image& image,
                               Table table,
                               std::uint16_t addr,
                               std::uint16_t qty) const noexcept = 0;
    /// Device ranges that no Modbus write may change (inputs, read-only specials).
    virtual const std::vector<image::Range>& read_only() const = 0;
};

/// The FBs map of SPEC §2, including the R3968/R3972/R3975 user maps.
const AddressMap& fbs_map();

}  // namespace plcemu::modbus
