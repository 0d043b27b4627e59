#include "plcemu/modbus/plc_unit.hpp"

namespace plcemu::modbus {

PlcUnit::PlcUnit(image::Image& image, const AddressMap& map, WritePolicy policy)
    : image_(image),
      map_(map) {
    set_policy(std::move(policy));
}

void PlcUnit::set_policy(WritePolicy policy) {
    read_only_ = policy.read_only;
    protected_ = map_.read_only();
    protected_.insert(protected_.end(), policy.write_protect.begin(), policy.write_protect.end());
}

Window PlcUnit::resolve(Table table, std::uint16_t addr, std::uint16_t qty, bool write) noexcept {
    const Resolution res = map_.resolve(image_, table, addr, qty);
    if (res.status != Status::Ok) return {res.status};
    if (write) {
        if (read_only_) return {Status::IllegalDataAddress};
        for (const auto& p : protected_) {
            if (p.overlaps(res.devices)) return {Status::IllegalDataAddress};
        }
    }
    Window w{Status::Ok};
    // A packed row (WM0) serves registers over bits: the window reads and writes them 16 a time.
    w.packed = res.packed;
    w.count = res.elements == qty ? 0 : res.elements;  // 0: the whole request
    if (image::is_bit_area(res.devices.area)) {
        w.bits = image_.bits(res.devices.area) + res.devices.start;
    } else {
        w.words = image_.words(res.devices.area) + res.devices.start;
    }
    return w;
}

std::optional<image::Range> PlcUnit::devices(Table table,
                                             std::uint16_t addr,
                                             std::uint16_t qty) const noexcept {
    const Resolution r = map_.resolve(image_, table, addr, qty == 0 ? 1 : qty);
    if (r.status != Status::Ok) return std::nullopt;
    return r.devices;
}

}  // namespace plcemu::modbus
