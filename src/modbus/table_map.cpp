// A Modbus map that is a table of rows, and the resolution every row-based map shares.

#include <algorithm>

#include "plcemu/modbus/address_map.hpp"

namespace plcemu::modbus {

const char* function_codes(Table table) {
    switch (table) {
        case Table::Coils:
            return "01 05 15";
        case Table::DiscreteInputs:
            return "02";
        case Table::HoldingRegisters:
            return "03 06 16 22 23";
        case Table::InputRegisters:
            return "04";
    }
    return "";
}

Resolution resolve_rows(const std::vector<MapRow>& rows,
                        const image::Image& img,
                        Table table,
                        std::uint16_t addr,
                        std::uint16_t qty) noexcept {
    std::uint32_t wire = addr;
    std::uint32_t left = qty;
    Resolution res;
    bool started = false;
    for (const auto& row : rows) {
        if (row.table != table) continue;
        const std::uint32_t row_end = std::uint32_t{row.wire_start} + row.count;
        if (wire < row.wire_start || wire >= row_end) continue;
        const std::uint32_t per = row.packed ? 16 : 1;
        const std::uint32_t dev = row.devices.start + per * (wire - row.wire_start);
        if (!started) {
            res.devices = {row.devices.area, dev, 0};
            res.packed = row.packed;
            started = true;
        } else if (row.devices.area != res.devices.area || dev != res.devices.end() ||
                   row.packed != res.packed) {
            break;  // another device range: the caller resolves the rest on its own
        }
        const std::uint32_t n = std::min(left, row_end - wire);
        res.devices.count += per * n;
        left -= n;
        wire += n;
        if (left == 0) break;
    }
    if (!started || !img.layout().contains(res.devices)) return {};
    res.elements = static_cast<std::uint16_t>(qty - left);
    res.status = Status::Ok;
    return res;
}

namespace {

class TableMap final : public AddressMap {
public:
    TableMap(std::vector<MapRow> rows, std::vector<image::Range> read_only)
        : rows_(std::move(rows)),
          read_only_(std::move(read_only)) {
        for (const auto& r : rows_) {
            if (r.read_only) read_only_.push_back(r.devices);
        }
    }

    const std::vector<MapRow>& rows() const override { return rows_; }
    std::vector<std::string> dynamic_notes() const override { return {}; }
    const std::vector<image::Range>& read_only() const override { return read_only_; }

    Resolution resolve(const image::Image& img,
                       Table table,
                       std::uint16_t addr,
                       std::uint16_t qty) const noexcept override {
        Resolution r = resolve_rows(rows_, img, table, addr, qty);
        // A table no row serves is not served at all.
        if (r.status != Status::Ok && !serves(table)) r.status = Status::IllegalFunction;
        return r;
    }

private:
    bool serves(Table t) const noexcept {
        return std::any_of(rows_.begin(), rows_.end(),
                           [&](const MapRow& r) { return r.table == t; });
    }

    std::vector<MapRow> rows_;
    std::vector<image::Range> read_only_;
};

}  // namespace

std::unique_ptr<AddressMap> make_table_map(std::vector<MapRow> rows,
                                           std::vector<image::Range> read_only) {
    return std::make_unique<TableMap>(std::move(rows), std::move(read_only));
}

}  // namespace plcemu::modbus
