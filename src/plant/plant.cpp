#include "plcemu/plant/plant.hpp"

#include "plcemu/plant/thermal_plant.hpp"

namespace plcemu::plant {

std::array<Drive, kChannels> drives_of(const engine::Declarations& program) {
    std::array<Drive, kChannels> d{};
    for (const auto& a : program.actuators) {
        if (a.channel < 0 || a.channel >= kChannels) continue;
        auto& slot = d[static_cast<std::size_t>(a.channel)];
        if (slot.kind != Drive::Kind::None) continue;  // the first declaration wins
        slot = {Drive::Kind::Output, a.output};
    }
    return d;
}

// The one place a model is chosen (docs/architecture.md, "Adding a plant model").
std::unique_ptr<Plant> make_plant(const PlantSetup& setup) {
    return std::make_unique<ThermalPlant>(setup);
}

}  // namespace plcemu::plant
