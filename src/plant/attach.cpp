// Wiring of the plant and the temperature measurement into an engine (SPEC §3 scan order).

#include "instructions/temperature_table.hpp"
#include "plcemu/plant/thermal_plant.hpp"

namespace plcemu::plant {

Attached attach(engine::Engine& engine, const config::Config& config) {
    Attached a;
    auto plant = ThermalPlant::from_config(config);
    a.plant = plant.get();
    // Inputs run in the order added, outputs in reverse: the plant advances to this scan's time
    // before the modules sample it, and latches the program's outputs after the program.
    engine.add_subsystem(std::move(plant));
    if (config.temperature.table) {
        auto m = instructions::make_temperature_table(config, *a.plant);
        a.measurement = m.get();
        engine.add_subsystem(std::move(m));
    }
    return a;
}

}  // namespace plcemu::plant
