#pragma once
// The PLC as a Modbus unit: its profile's address map over the register image, with the
// write protections of the profile and of the config.

#include <vector>

#include "plcemu/image/image.hpp"
#include "plcemu/modbus/address_map.hpp"
#include "plcemu/modbus/unit.hpp"

namespace plcemu::modbus {

/// Write restrictions from the config (the map's read-only items are always added).
struct WritePolicy {
    bool read_only = false;                   ///< refuse every write
    std::vector<image::Range> write_protect;  ///< device ranges writes may not touch
};

/// The PLC unit.
class PlcUnit final : public Unit {
public:
    /// `image` and `map` must outlive the unit.
    PlcUnit(image::Image& image, const AddressMap& map, WritePolicy policy);

    Window resolve(Table table,
                   std::uint16_t addr,
                   std::uint16_t qty,
                   bool write) noexcept override;
    std::optional<image::Range> devices(Table table,
                                        std::uint16_t addr,
                                        std::uint16_t qty) const noexcept override;

    /// Replaces the write policy (config reload).
    void set_policy(WritePolicy policy);
    /// The device ranges writes may not touch: the map's read-only items and the policy's.
    const std::vector<image::Range>& protected_ranges() const { return protected_; }

private:
    image::Image& image_;
    const AddressMap& map_;
    bool read_only_ = false;
    std::vector<image::Range> protected_;
};

}  // namespace plcemu::modbus
