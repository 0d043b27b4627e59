// The FATEK Modbus slave table (FBs manual 13-50/51; docs/profile-fbs.md, "Modbus map").

#include "profiles/fatek/map_rows.hpp"

namespace plcemu::profiles::fatek {

using image::Area;
using modbus::MapRow;
using modbus::Table;

std::vector<MapRow> map_rows() {
    return {
        {Table::Coils, 0, 256, {Area::Y, 0, 256}, "01 05 15", "Y0-Y255"},
        {Table::Coils, 1000, 256, {Area::X, 0, 256}, "01", "X0-X255"},
        {Table::Coils, 2000, 2002, {Area::M, 0, 2002}, "01 05 15", "M0-M2001"},
        {Table::Coils, 6000, 1000, {Area::S, 0, 1000}, "01 05 15", "S0-S999"},
        {Table::Coils, 9000, 256, {Area::T, 0, 256}, "01 05 15", "T0-T255 status"},
        {Table::Coils, 9500, 256, {Area::C, 0, 256}, "01 05 15", "C0-C255 status"},
        {Table::HoldingRegisters, 0, 4168, {Area::R, 0, 4168}, "03 06 16 22 23", "R0-R4167"},
        {Table::HoldingRegisters, 5000, 999, {Area::R, 5000, 999}, "03 06 16 22 23", "R5000-R5998"},
        {Table::HoldingRegisters, 6000, 2999, {Area::D, 0, 2999}, "03 06 16 22 23", "D0-D2998"},
        {Table::HoldingRegisters,
         9000,
         256,
         {Area::TV, 0, 256},
         "03 06 16 22 23",
         "T0-T255 current value"},
        {Table::HoldingRegisters,
         9500,
         200,
         {Area::CV, 0, 200},
         "03 06 16 22 23",
         "C0-C199 current value"},
        {Table::HoldingRegisters,
         9700,
         112,
         {Area::CV, 200, 112},
         "03 06 16 22 23",
         "C200-C255 current value, 2 words each, low word first"},
    };
}

std::vector<image::Range> read_only() {
    return {
        {Area::X, 0, 256},    // inputs come from the simulator
        {Area::R, 3840, 64},  // IR
        {Area::M, 1920, 8},   // clocks, first scan, RUN…
        {Area::R, 4136, 3},   // scan times
    };
}

}  // namespace plcemu::profiles::fatek
