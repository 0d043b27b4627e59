#include "plcemu/daemon/plc.hpp"

#include "plcemu/instructions/instructions.hpp"
#include "plcemu/modbus/address_map.hpp"
#include "version.hpp"

namespace plcemu::daemon {

const char* version() { return PLCEMU_VERSION; }

Plc::Plc(const config::Config& config, std::span<std::byte> storage)
    : config_(config) {
    image::Layout layout = image::layout_for(config_.profile);
    if (config_.persistence.retentive) layout.retentive = *config_.persistence.retentive;
    if (storage.empty()) {
        image_ = std::make_unique<image::Image>(layout);
    } else {
        image_ = std::make_unique<image::Image>(layout, storage);
        image_->clear_non_retentive(layout.retentive);
    }

    engine::EngineOptions eo;
    eo.scan_period = std::chrono::milliseconds(config_.scan_ms);
    eo.station = config_.station;
    eo.model_code = config::model_code(config_.model).value_or(0);
    engine_ = std::make_unique<engine::Engine>(*image_, eo,
                                               instructions::make_program(config_, layout));
    engine_->power_up();
    apply_init();

    modbus::WritePolicy policy{config_.modbus.read_only, config_.modbus.write_protect};
    unit_ = std::make_unique<modbus::PlcUnit>(*image_, modbus::fbs_map(), policy);
    dispatcher_ = std::make_unique<modbus::Dispatcher>(
        *unit_, engine_->station(), modbus::Identity{"FATEK", config_.model, version()});
    dispatcher_->set_unknown_unit_policy(config_.modbus.tcp.unknown_unit ==
                                                 config::UnknownUnit::Silent
                                             ? modbus::UnknownUnitPolicy::Silent
                                             : modbus::UnknownUnitPolicy::Exception);
}

Plc::~Plc() = default;

void Plc::apply_init() {
    const image::Layout& layout = image_->layout();
    for (const auto& e : config_.init) {
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
            if (image::is_bit_area(d.area) && !d.word_of_bits) {
                image_->write_bit(d, e.values[i] != 0);
            } else {
                image_->write_word(d, e.values[i]);
            }
        }
    }
}

}  // namespace plcemu::daemon
