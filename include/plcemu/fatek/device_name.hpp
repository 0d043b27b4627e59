#pragma once
// How a FATEK master writes a device (FBs manual, Appendix 2 FATEK Communication Protocol;
// docs/profile-fbs.md, "FATEK protocol"), for the listings that show it beside its Modbus
// address (--print-map, --export-tags).

#include <cstdint>
#include <string>

#include "plcemu/image/area.hpp"
#include "plcemu/image/layout.hpp"

namespace plcemu::fatek {

/// The name of device `index` of `area` of a PLC of `layout` in a FATEK frame: "X0000",
/// "R00100", "D00010", "RT0005", "RC0007", "DRC0200" (a 32-bit counter, named at its low word),
/// "WM0000" (with `word_of_bits`: the 16 discretes from it, at a multiple of 8). Empty for a
/// device the protocol cannot name: a 32-bit counter's high word, a W form off the multiples of
/// 8, a number wider than the name's digits. The prefixes and the counters' split are the
/// protocol's parser's (src/fatek/names.cpp).
std::string device_name(const image::Layout& layout,
                        image::Area area,
                        std::uint32_t index,
                        bool word_of_bits = false);

}  // namespace plcemu::fatek
