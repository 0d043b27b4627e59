#pragma once
// The special modules on a PLC's extension bus as the program reaches them: each module has a
// buffer memory of numbered words, read with FROM and written with TO (VB manual FNC88/FNC92
// examples: `FROM K1 K32 D0 K8`, `TOP K1 K0 K7 K8`). A family that has such modules attaches
// its bus to the engine; the instructions see it in ScanContext::modules.

#include <cstdint>

namespace plcemu::engine {

/// The modules of one PLC, numbered from 1 in bus order.
class ModuleBus {
public:
    virtual ~ModuleBus() = default;
    /// Buffer word `word` of module `module` into `out`; false when there is no such word.
    virtual bool read(int module, int word, std::uint16_t& out) noexcept = 0;
    /// Writes buffer word `word` of module `module`; false when there is no such word.
    virtual bool write(int module, int word, std::uint16_t value) noexcept = 0;
};

}  // namespace plcemu::engine
