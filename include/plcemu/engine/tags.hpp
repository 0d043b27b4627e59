#pragma once
// What devices mean, for the tag export (`plcemud --export-tags`, docs/configuration.md, "Tag
// export"): a profile describes its special devices and the areas its subsystems use, an
// instruction its operands and working blocks; the export finds their Modbus addresses. Nothing
// here runs during a scan.

#include <cstdint>
#include <string>
#include <vector>

#include "plcemu/image/area.hpp"

namespace plcemu::engine {

/// How an HMI reads a word: a signed value (a temperature, a set point) or bits and codes.
enum class Number : std::uint8_t { Signed, Unsigned };

/// Devices with one meaning. A range of several devices is one meaning per device ("TPCTL SV"
/// for each point): the export numbers them. A counter value range holds counter words (a
/// 32-bit counter's two words are one device).
struct Tag {
    image::Range devices;            ///< the devices
    std::string description;         ///< what they hold, one line
    Number number = Number::Signed;  ///< how their words read (bits: ignored)
};

/// Tags in the order they were described.
using Tags = std::vector<Tag>;

}  // namespace plcemu::engine
