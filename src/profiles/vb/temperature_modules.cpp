#include "profiles/vb/temperature_modules.hpp"

#include <cmath>

namespace plcemu::profiles::vb {

namespace {

// The ranges the readings cover, °C. K type: −50.0…+500.0 °C (VB manual FNC88 example, mode
// 7). Pt100: the manual gives none; −200.0…+600.0 °C, the usual Pt100 module span
// (docs/profile-vb.md, "Temperature modules").
struct Span {
    double lo;
    double hi;
};
constexpr Span kThermocouple{-50.0, 500.0};
constexpr Span kPt100{-200.0, 600.0};

}  // namespace

TemperatureModules::TemperatureModules(const std::vector<ModuleConfig>& modules,
                                       engine::SensorSource& sensors)
    : sensors_(sensors) {
    int channel = 0;
    for (const ModuleConfig& c : modules) {
        Module m;
        m.config = c;
        m.first_channel = channel;
        for (std::size_t i = 0; i < static_cast<std::size_t>(c.channels); ++i) {
            m.buffer[cr::kMode + i] = c.mode;
        }
        channel += c.channels;
        modules_.push_back(m);
    }
}

std::uint16_t TemperatureModules::reading(const Module& m, int channel) noexcept {
    const engine::SensorSample s = sensors_.sense(m.first_channel + channel);
    const Span span = m.config.sensor == Sensor::Pt100 ? kPt100 : kThermocouple;
    if (s.broken || !(s.celsius >= span.lo && s.celsius <= span.hi)) return cr::kBroken;
    return static_cast<std::uint16_t>(static_cast<std::int16_t>(std::lround(s.celsius * 10.0)));
}

void TemperatureModules::inputs(engine::ScanContext& /*ctx*/) noexcept {
    for (Module& m : modules_) {
        // Ready from the first scan, whatever a TO wrote there.
        m.buffer[cr::kStatus] = cr::kReady;
        m.buffer[cr::kStatusAlt] = cr::kReady;
        for (int i = 0; i < m.config.channels; ++i) {
            // Mode 0 disables the channel (reads 0); any other code measures.
            const auto at = static_cast<std::size_t>(i);
            m.buffer[cr::kReadings + at] = m.buffer[cr::kMode + at] == 0 ? 0 : reading(m, i);
        }
    }
}

std::uint16_t* TemperatureModules::at(int module, int word) noexcept {
    if (module < 1 || module > static_cast<int>(modules_.size()) || word < 0 ||
        word >= cr::kWords) {
        return nullptr;
    }
    return &modules_[static_cast<std::size_t>(module - 1)].buffer[static_cast<std::size_t>(word)];
}

bool TemperatureModules::read(int module, int word, std::uint16_t& out) noexcept {
    const std::uint16_t* w = at(module, word);
    if (w != nullptr) out = *w;
    return w != nullptr;
}

bool TemperatureModules::write(int module, int word, std::uint16_t value) noexcept {
    std::uint16_t* w = at(module, word);
    if (w != nullptr) *w = value;
    return w != nullptr;
}

}  // namespace plcemu::profiles::vb
