#pragma once
// The VB `modules:` section: the special temperature modules on the extension bus, in bus order
// (VB manual FNC88/FNC92 examples: `FROM K1 …` reads module 1; docs/profile-vb.md,
// "Temperature modules").

#include <cstdint>
#include <vector>

#include "plcemu/config/config.hpp"
#include "plcemu/config/reader.hpp"

namespace plcemu::profiles::vb {

/// What a module measures.
enum class Sensor : std::uint8_t { Thermocouple, Pt100 };

/// One module of `modules:`.
struct ModuleConfig {
    const char* type = "";                 ///< VB-8T, VB-4T, VB-4PT or VB-2PT
    int channels = 0;                      ///< 8, 4, 4 or 2
    Sensor sensor = Sensor::Thermocouple;  ///< thermocouple (K) or Pt100
    std::uint16_t mode = 7;                ///< power-up mode of every channel (CR#0…)
    config::Position pos;                  ///< where it stands
};

/// Modules on one PLC, at most.
inline constexpr std::size_t kMaxModules = 8;

/// Reads a `modules:` section with `r`, each entry on its own: an error is recorded where `r`
/// records errors (else thrown) and the other entries are still read.
std::vector<ModuleConfig> read_modules(const config::Reader& r, const config::Node& section);

}  // namespace plcemu::profiles::vb
