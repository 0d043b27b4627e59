// The VB Modbus slave map (docs/profile-vb.md, "Modbus map"). VIGOR publishes no slave map; this
// one follows the FX3U MODBUS default allocation (FX3U MODBUS manual (JY997D26201) §9.3): coils
// and discrete inputs share addresses, X exists only as discrete inputs, the special M/D area
// moves from 8000 to 9000.

#include "profiles/vb/map.hpp"

#include "profiles/vb/specials.hpp"

namespace plcemu::profiles::vb {

namespace {

using image::Area;
using image::Range;
using modbus::MapRow;
using modbus::Table;

// One row, served by two tables (coils and discrete inputs, holding and input registers).
struct Row {
    std::uint16_t wire;
    Range devices;
    const char* label;
};

// FX3U MODBUS manual (JY997D26201) §9.3, bit devices, with the VB's M9000 for M8000.
constexpr Row kBits[] = {
    {0x0000, {Area::M, 0, 3072}, "M0-M3071"},
    {0x1E00, {Area::M, 9000, 256}, "M9000-M9255 (special)"},
    {0x2000, {Area::S, 0, 1000}, "S0-S999"},
    {0x3000, {Area::T, 0, 256}, "T0-T255 contacts"},
    {0x3200, {Area::C, 0, 256}, "C0-C255 contacts"},
    {0x3300, {Area::Y, 0, 256}, "Y0-Y377 (octal)"},
};

// D as FX numbers it (D9000 right after D7999, as FX3U D8000 at 1F40h); timer and counter
// values where the FBs map has them, so one SCADA template reads both families.
constexpr Row kWords[] = {
    {0, {Area::D, 0, 8000}, "D0-D7999"},
    {8000, {Area::D, 9000, 256}, "D9000-D9255 (special)"},
    {9000, {Area::TV, 0, 256}, "TN0-TN255 (timer values)"},
    {9500, {Area::CV, 0, 200}, "CN0-CN199 (counter values)"},
    {9700, {Area::CV, 200, 112}, "CN200-CN255 (32-bit, 2 words each, low word first)"},
};

std::vector<MapRow> rows() {
    std::vector<MapRow> r;
    for (const auto& b : kBits) {
        r.push_back({Table::Coils, b.wire, static_cast<std::uint16_t>(b.devices.count), b.devices,
                     modbus::function_codes(Table::Coils), b.label});
    }
    for (const auto& b : kBits) {
        r.push_back({Table::DiscreteInputs, b.wire, static_cast<std::uint16_t>(b.devices.count),
                     b.devices, modbus::function_codes(Table::DiscreteInputs), b.label});
    }
    // X only as discrete inputs: FC01/05/15 at 3400h get exception 02.
    r.push_back({Table::DiscreteInputs,
                 0x3400,
                 256,
                 {Area::X, 0, 256},
                 modbus::function_codes(Table::DiscreteInputs),
                 "X0-X377 (octal)"});
    for (const auto& w : kWords) {
        r.push_back({Table::HoldingRegisters, w.wire, static_cast<std::uint16_t>(w.devices.count),
                     w.devices, modbus::function_codes(Table::HoldingRegisters), w.label});
    }
    for (const auto& w : kWords) {
        r.push_back({Table::InputRegisters, w.wire, static_cast<std::uint16_t>(w.devices.count),
                     w.devices, modbus::function_codes(Table::InputRegisters), w.label});
    }
    return r;
}

const std::vector<Range>& read_only() {
    namespace sp = special;
    static const std::vector<Range> kReadOnly{
        {Area::X, 0, 256},             // inputs come from the simulator
        {Area::M, sp::kRun, 4},        // M9000–M9003: RUN, OFF, first scan, after first scan
        {Area::M, sp::kClock10ms, 4},  // M9011–M9014: clocks
        {Area::D, sp::kScanTime, 3},   // D9010–D9012: scan times
    };
    return kReadOnly;
}

}  // namespace

const modbus::AddressMap& map() {
    static const auto kMap = modbus::make_table_map(rows(), read_only());
    return *kMap;
}

}  // namespace plcemu::profiles::vb
