#include "plcemu/daemon/plc.hpp"

#include "plcemu/instructions/instructions.hpp"
#include "plcemu/instructions/listing.hpp"
#include "plcemu/modbus/address_map.hpp"
#include "plcemu/modbus/function_handler.hpp"
#include "plcemu/profiles/profile.hpp"
#include "version.hpp"

namespace plcemu::daemon {

const char* version() { return PLCEMU_VERSION; }

image::Layout plc_layout(const config::Config& config) {
    const profiles::Profile& profile = profiles::of(config);
    image::Layout layout = profile.layout();
    layout.name_of_family = &profiles::family_name;
    if (config.persistence.retentive) layout.retentive = *config.persistence.retentive;
    // What the family keeps whatever the config makes retentive (a power-up counter).
    for (const auto& always : profile.always_retentive()) {
        bool covered = false;
        for (const auto& r : layout.retentive) covered = covered || r.contains(always);
        if (!covered) layout.retentive.push_back(always);
    }
    return layout;
}

namespace {

instructions::Where where_of(const config::Position& p) { return {p.file.str(), p.line, p.column}; }

config::ConfigError config_error(const instructions::BindError& e) {
    const auto& w = e.where();
    return config::ConfigError({w.file, w.line, w.column}, e.what());
}

engine::Program build_listing(const config::Config& config,
                              engine::Tags* operands,
                              std::vector<instructions::ListingWarning>* warnings) {
    const profiles::Profile& profile = profiles::of(config);
    const auto statements = profiles::listing_statements(config);
    const instructions::Dialect& dialect = *profile.listing();
    const auto services = profile.services(config);
    try {
        return instructions::make_listing_program(statements, dialect, profile.instructions(),
                                                  plc_layout(config), profile.naming(), *services,
                                                  warnings, operands);
    } catch (const instructions::BindError& e) {
        throw config_error(e);
    }
}

}  // namespace

engine::Program build_program(const config::Config& config,
                              engine::Tags* operands,
                              std::vector<std::string>* warnings) {
    if (!config.listing.empty()) {
        std::vector<instructions::ListingWarning> found;
        engine::Program p = build_listing(config, operands, warnings ? &found : nullptr);
        for (const auto& w : found) warnings->push_back(w.where.text() + ": " + w.message);
        return p;
    }
    const profiles::Profile& profile = profiles::of(config);
    const auto services = profile.services(config);
    std::vector<instructions::Entry> entries;
    entries.reserve(config.program.size());
    for (const auto& ic : config.program) {
        instructions::Entry e{
            ic.mnemonic, where_of(ic.pos), {}, static_cast<int>(entries.size()) + 1};
        e.operands.reserve(ic.operands.size());
        for (const auto& [key, op] : ic.operands) {
            e.operands.emplace_back(key, instructions::Operand{op.text, where_of(op.pos)});
        }
        entries.push_back(std::move(e));
    }
    try {
        return instructions::make_program(entries, profile.instructions(), plc_layout(config),
                                          profile.naming(), *services, operands);
    } catch (const instructions::BindError& e) {
        throw config_error(e);
    }
}

std::string print_program(const config::Config& config) {
    if (!config.listing.empty()) {
        return instructions::format_listing(profiles::listing_statements(config));
    }
    // Entries print as statements of their own: the mnemonic, then each operand by its key.
    std::vector<instructions::Statement> statements;
    for (const auto& ic : config.program) {
        instructions::Statement s;
        s.mnemonic = ic.mnemonic;
        s.step = static_cast<int>(statements.size()) + 1;
        for (const auto& [key, op] : ic.operands) {
            s.named.emplace_back(key, instructions::Operand{op.text, where_of(op.pos)});
        }
        statements.push_back(std::move(s));
    }
    return instructions::format_listing(statements);
}

plant::PlantSetup plant_setup(const config::Config& config, const engine::Declarations& program) {
    const auto declared = plant::drives_of(program);
    plant::PlantSetup setup;
    setup.seed = config.plant.seed;
    for (std::size_t i = 0; i < setup.channels.size(); ++i) {
        config::ChannelConfig cc = config.plant.defaults;
        for (const auto& [idx, c] : config.plant.channels) {
            if (static_cast<std::size_t>(idx) == i) cc = c;
        }
        plant::ChannelSetup& ch = setup.channels[i];
        ch.params = cc.params;
        ch.faults = cc.faults;
        // `plant.channels.N.drive` wins over the output the program declares for the channel.
        ch.drive = declared[i];
        if (cc.drive) {
            const bool output = cc.drive->area == image::Area::Y;
            ch.drive = {output ? plant::Drive::Kind::Output : plant::Drive::Kind::Register,
                        *cc.drive,
                        static_cast<double>(
                            cc.drive_full_scale.value_or(profiles::of(config).drive_full_scale()))};
        }
    }
    return setup;
}

std::unique_ptr<modbus::AddressMap> map_of(const config::Config& config) {
    if (!config.modbus.map) return nullptr;
    const profiles::Profile& profile = profiles::of(config);
    std::vector<modbus::MapRow> rows;
    for (const auto& r : *config.modbus.map) {
        modbus::MapRow row;
        constexpr modbus::Table kTables[] = {
            modbus::Table::Coils, modbus::Table::DiscreteInputs, modbus::Table::HoldingRegisters,
            modbus::Table::InputRegisters};  // config::MapTable's order
        row.table = kTables[static_cast<std::size_t>(r.table)];
        row.codes = modbus::function_codes(row.table);
        row.wire_start = r.start;
        row.count = r.count;
        row.packed = r.device.word_of_bits;
        row.devices = {r.device.area, r.device.index,
                       static_cast<std::uint32_t>(r.count) * (row.packed ? 16u : 1u)};
        row.read_only = r.read_only;
        row.label = profile.naming().format_range(row.devices);
        if (row.packed) row.label += ", 16 per register, low bit first";
        rows.push_back(std::move(row));
    }
    // The family's read-only devices (inputs, specials) stay read-only under any map.
    return modbus::make_table_map(std::move(rows), profile.map().read_only());
}

Plc::Plc(const config::Config& config,
         std::span<std::byte> storage,
         Start start,
         std::optional<engine::Program> program,
         std::optional<std::vector<image::Range>> kept)
    : Plc(std::make_shared<const config::Config>(config),
          storage,
          start,
          std::move(program),
          std::move(kept)) {}

Plc::Plc(std::shared_ptr<const config::Config> config,
         std::span<std::byte> storage,
         Start start,
         std::optional<engine::Program> program,
         std::optional<std::vector<image::Range>> kept)
    : config_(std::move(config)),
      start_(storage.empty() ? Start::Fresh : start),
      kept_(start_ == Start::Retained ? std::move(kept) : std::nullopt) {
    image::Layout layout = plc_layout(*config_);
    if (storage.empty()) {
        image_ = std::make_unique<image::Image>(layout);
    } else {
        image_ = std::make_unique<image::Image>(layout, storage);
        // A reload keeps the live image as it is; a start clears what is not retained.
        if (start_ != Start::Reload) image_->clear_non_retentive(layout.retentive);
    }

    const profiles::Profile& profile = profiles::of(*config_);
    engine::EngineOptions eo;
    eo.scan_period = std::chrono::milliseconds(config_->scan_ms);
    eo.station = config_->station;
    engine_ = std::make_unique<engine::Engine>(
        *image_, eo, program ? std::move(*program) : build_program(*config_),
        profile.specials(*config_));
    if (start_ == Start::Reload) {
        engine_->reload();
    } else {
        engine_->power_up();
    }
    apply_init();
    // The plant and the measurement before the program, the outputs to the plant after it
    // (docs/architecture.md, "A scan"): the plant attaches to the outputs the program declares.
    auto plant =
        plant::make_plant(plant_setup(*config_, engine::declarations_of(engine_->program())));
    plant_ = plant.get();
    engine_->add_subsystem(std::move(plant));
    profile.attach(*engine_, *config_, *plant_);

    map_ = map_of(*config_);
    // Program data (file registers) is as write-protected as what the config protects.
    modbus::WritePolicy policy{config_->modbus.read_only, config_->modbus.write_protect};
    for (const auto& r : profile.program_data(*config_)) policy.write_protect.push_back(r);
    unit_ = std::make_unique<modbus::PlcUnit>(*image_, map_ ? *map_ : profile.map(), policy);
    const std::string model =
        config_->model.empty() ? std::string(profile.default_model()) : config_->model;
    dispatcher_ = std::make_unique<modbus::Dispatcher>(
        modbus::Identity{std::string(profile.vendor()), model, version()});
    for (const auto& [fc, handler] : profile.functions()) dispatcher_->set_function(fc, handler);
}

Plc::~Plc() = default;

void Plc::apply_init() {
    const image::Layout& layout = image_->layout();
    const bool spare_retained =
        start_ != Start::Fresh && config_->persistence.init == config::InitPolicy::Fresh;
    // Program data takes its presets at every start and reload, as part of the program.
    const auto program_data = profiles::of(*config_).program_data(*config_);
    auto retentive = [&](image::Area a, std::uint32_t index) {
        for (const auto& r : program_data) {
            if (r.area == a && index >= r.start && index < r.end()) return false;
        }
        const auto in = [&](const std::vector<image::Range>& ranges) {
            for (const auto& r : ranges) {
                if (r.area == a && index >= r.start && index < r.end()) return true;
            }
            return false;
        };
        // A device retentive now but not when the storage was last used was cleared at this
        // start: nothing retained to spare, its preset applies.
        return in(layout.retentive) && (!kept_ || in(*kept_));
    };
    for (const auto& e : config_->init) {
        // The loader refused this at the entry's key; a config made in code meets it here
        // rather than write past an area.
        if (!layout.contains(e.range())) {
            throw config::ConfigError(
                e.pos,
                "init: " + config::outside(profiles::of(*config_).naming(), layout, e.range()));
        }
        for (std::size_t i = 0; i < e.values.size(); ++i) {
            image::Device d = e.device;
            d.index += static_cast<std::uint32_t>(i) * e.step();
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
