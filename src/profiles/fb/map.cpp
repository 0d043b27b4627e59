// The FB Modbus slave map (docs/profile-fb.md, "Modbus map"). The FB manuals give no Modbus
// table; FATEK's, documented for the FBs, is the only FATEK numbering a master can use. Its user
// remap is left out: on an FB, R3968–R3999 are the raw temperature readings TP0–TP31 (FB manual
// FUN72/FUN73), which the measurement rewrites, so live data would switch maps on and off.

#include "profiles/fb/map.hpp"

#include <algorithm>

#include "profiles/fatek/map_rows.hpp"
#include "profiles/fb/special_registers.hpp"

namespace plcemu::profiles::fb {

namespace {

using image::Area;
using modbus::MapRow;
using modbus::Table;

// FATEK's rows with R0–R4167 cut in three, so that --print-map shows what R3968–R3999 are here.
std::vector<MapRow> fb_rows() {
    std::vector<MapRow> rows = fatek::map_rows();
    const auto r = std::find_if(rows.begin(), rows.end(), [](const MapRow& m) {
        return m.table == Table::HoldingRegisters && m.devices.area == Area::R &&
               m.devices.start == 0;
    });
    const MapRow whole = *r;
    constexpr std::uint16_t kRaw = special::kRawReadings;
    constexpr std::uint16_t kAfter = kRaw + special::kPoints;
    MapRow before = whole;
    before.count = kRaw;
    before.devices.count = kRaw;
    before.label = "R0-R3967";
    MapRow raw = whole;
    raw.wire_start = kRaw;
    raw.count = special::kPoints;
    raw.devices = {Area::R, kRaw, special::kPoints};
    raw.label = "R3968-R3999: raw temperature readings (no user remap in profile fb)";
    MapRow after = whole;
    after.wire_start = kAfter;
    after.count = static_cast<std::uint16_t>(whole.count - kAfter);
    after.devices = {Area::R, kAfter, after.count};
    after.label = "R4000-R4167";
    *r = after;
    rows.insert(r, {before, raw});
    return rows;
}

}  // namespace

const modbus::AddressMap& map() {
    // No FC02/FC04 rows: without the R3972–R3977 maps those codes reach nothing, as on an FBs
    // whose counts are 0 (exception 01).
    static const auto kMap = modbus::make_table_map(fb_rows(), fatek::read_only());
    return *kMap;
}

}  // namespace plcemu::profiles::fb
