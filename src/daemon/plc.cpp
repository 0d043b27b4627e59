#include "plcemu/daemon/plc.hpp"

#include "plcemu/engine/special.hpp"
#include "plcemu/instructions/instructions.hpp"
#include "plcemu/modbus/address_map.hpp"
#include "version.hpp"

namespace plcemu::daemon {

const char* version() { return PLCEMU_VERSION; }

image::Layout plc_layout(const config::Config& config) {
    image::Layout layout = image::layout_for(config.profile);
    if (config.persistence.retentive) layout.retentive = *config.persistence.retentive;
    // SPEC §3: R4057 counts starts, whatever the config makes retentive.
    const image::Range power_ups{image::Area::R, engine::special::kPowerUps, 1};
    bool covered = false;
    for (const auto& r : layout.retentive) covered = covered || r.contains(power_ups);
    if (!covered) layout.retentive.push_back(power_ups);
    return layout;
}

Plc::Plc(const config::Config& config,
         std::span<std::byte> storage,
         Start start,
         std::optional<engine::Program> program)
    : Plc(std::make_shared<const config::Config>(config), storage, start, std::move(program)) {}

Plc::Plc(std::shared_ptr<const config::Config> config,
         std::span<std::byte> storage,
         Start start,
         std::optional<engine::Program> program)
    : config_(std::move(config)),
      start_(storage.empty() ? Start::Fresh : start) {
    image::Layout layout = plc_layout(*config_);
    if (storage.empty()) {
        image_ = std::make_unique<image::Image>(layout);
    } else {
        image_ = std::make_unique<image::Image>(layout, storage);
        // A reload keeps the live image as it is; a start clears what is not retained.
        if (start_ != Start::Reload) image_->clear_non_retentive(layout.retentive);
    }

    engine::EngineOptions eo;
    eo.scan_period = std::chrono::milliseconds(config_->scan_ms);
    eo.station = config_->station;
    eo.model_code = config::model_code(config_->model).value_or(0);
    engine_ = std::make_unique<engine::Engine>(
        *image_, eo, program ? std::move(*program) : instructions::make_program(*config_, layout));
    if (start_ != Start::Reload) engine_->power_up();
    apply_init();
    // SPEC §3: the plant and the temperature readings before the program, outputs to the plant
    // after it.
    plant_ = plant::attach(*engine_, *config_).plant;

    modbus::WritePolicy policy{config_->modbus.read_only, config_->modbus.write_protect};
    unit_ = std::make_unique<modbus::PlcUnit>(*image_, modbus::fbs_map(), policy);
    dispatcher_ = std::make_unique<modbus::Dispatcher>(
        *unit_, engine_->station(), modbus::Identity{"FATEK", config_->model, version()});
    dispatcher_->set_unknown_unit_policy(config_->modbus.tcp.unknown_unit ==
                                                 config::UnknownUnit::Silent
                                             ? modbus::UnknownUnitPolicy::Silent
                                             : modbus::UnknownUnitPolicy::Exception);
}

Plc::~Plc() = default;

void Plc::apply_init() {
    const image::Layout& layout = image_->layout();
    const bool spare_retained =
        start_ != Start::Fresh && config_->persistence.init == config::InitPolicy::Fresh;
    auto retentive = [&](image::Area a, std::uint32_t index) {
        for (const auto& r : layout.retentive) {
            if (r.area == a && index >= r.start && index < r.end()) return true;
        }
        return false;
    };
    for (const auto& e : config_->init) {
        const std::uint32_t per = e.device.word_of_bits ? 16 : 1;
        const image::Range r{e.device.area, e.device.index,
                             static_cast<std::uint32_t>(e.values.size()) * per};
        if (!layout.contains(r)) {
            throw config::ConfigError(e.pos, "init: " + image::format_range(r) +
                                                 " is outside this PLC's " +
                                                 std::string(image::area_name(r.area)) + " area");
        }
        for (std::size_t i = 0; i < e.values.size(); ++i) {
            image::Device d = e.device;
            d.index += static_cast<std::uint32_t>(i) * per;
            std::uint16_t v = e.values[i];
            if (spare_retained) {
                // Retained values win over presets: keep every retentive bit or word as it is.
                if (d.word_of_bits) {
                    const std::uint16_t old = image_->read_word(d);
                    for (std::uint32_t b = 0; b < 16; ++b) {
                        if (!retentive(d.area, d.index + b)) continue;
                        const auto mask = static_cast<std::uint16_t>(1u << b);
                        v = static_cast<std::uint16_t>((v & ~mask) | (old & mask));
                    }
                } else if (retentive(d.area, d.index)) {
                    continue;
                }
            }
            if (image::is_bit_area(d.area) && !d.word_of_bits) {
                image_->write_bit(d, v != 0);
            } else {
                image_->write_word(d, v);
            }
        }
    }
}

}  // namespace plcemu::daemon
