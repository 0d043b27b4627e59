// The FATEK FBs profile: the device areas and retentive ranges of the FBs manual, its Modbus
// table (13-50/51), the special relays and registers, the A556h temperature measurement and
// FUN86 TPCTL (FBs manual §21.3, §21.7). docs/profile-fbs.md describes it for users.

#include "instructions/mov.hpp"
#include "plcemu/profiles/profile.hpp"
#include "profiles/fatek/layout.hpp"
#include "profiles/fatek/listing.hpp"
#include "profiles/fatek/naming.hpp"
#include "profiles/fbs/map.hpp"
#include "profiles/fbs/model.hpp"
#include "profiles/fbs/services.hpp"
#include "profiles/fbs/special_registers.hpp"
#include "profiles/fbs/specials.hpp"
#include "profiles/fbs/temperature_config.hpp"
#include "profiles/fbs/temperature_table.hpp"
#include "profiles/fbs/tpctl.hpp"

namespace plcemu::profiles::fbs {

namespace {

using image::Area;

class Fbs final : public Profile {
public:
    std::string_view name() const override { return "fbs"; }
    std::string_view title() const override { return "FATEK FBs"; }
    std::uint32_t family() const override { return 0; }
    std::string_view vendor() const override { return "FATEK"; }
    std::string_view default_model() const override { return "FBs-24MC"; }
    bool valid_model(std::string_view model) const override {
        return model_code(model).has_value();
    }
    std::string_view model_hint() const override { return "an FBs model such as FBs-24MC"; }
    int max_station() const override { return 254; }
    const image::Naming& naming() const override { return naming_; }

    image::Layout layout() const override { return fatek::make_layout(family(), name(), 4000); }

    std::vector<image::Range> always_retentive() const override {
        // R4057 counts starts, whatever the config makes retentive.
        return {{Area::R, special::kPowerUps, 1}};
    }

    std::vector<std::string_view> sections() const override { return {"temperature"}; }
    // Port 0 of every FATEK PLC speaks FATEK's own protocol (FBs manual, chapter 11).
    std::vector<std::string_view> protocols() const override { return {"fatek"}; }
    std::shared_ptr<const config::ProfileSettings> read(const config::Config& config,
                                                        const config::Reader& r) const override {
        return read_settings(config, r);
    }

    const modbus::AddressMap& map() const override { return fbs::map(); }

    const instructions::Table& instructions() const override {
        static const instructions::Table kTable{
            {"MOV", &instructions::make_mov},
            {"TPCTL", &make_tpctl},
        };
        return kTable;
    }

    // WinProladder's mnemonic view, with the functions this profile has.
    const instructions::Dialect* listing() const override {
        static const instructions::Dialect kDialect = fatek::listing_dialect({
            {"MOV", 8, {"s", "d"}, true},
            {"TPCTL", 86, {}, false},
        });
        return &kDialect;
    }

    std::unique_ptr<instructions::Services> services(const config::Config& config) const override {
        auto s = std::make_unique<Services>();
        s->timers = fatek::timer_groups();
        s->temperature_table = settings_of(config)->temperature.table;
        if (const auto own = temperature::module_outputs(config)) {
            s->reserved_outputs.emplace_back(
                *own,
                "the digital outputs of the temperature modules in temperature.modules (each "
                "module occupies 8 DO; the program cannot drive them)");
        }
        return s;
    }

    std::unique_ptr<engine::Specials> specials(const config::Config& config) const override {
        return make_specials(model_code(config.model).value_or(0));
    }

    engine::Tags tags(const config::Config& config, const image::Image& image) const override {
        engine::Tags t = special_tags();
        for (auto& m : map_tags()) t.push_back(std::move(m));
        for (auto& m : temperature_tags(config, image)) t.push_back(std::move(m));
        return t;
    }

    void attach(engine::Engine& engine,
                const config::Config& config,
                engine::SensorSource& sensors) const override {
        // The measurement samples the plant before the program reads its readings.
        if (settings_of(config)->temperature.table)
            engine.add_subsystem(make_temperature_table(config, sensors));
    }

private:
    image::Naming naming_ = fatek::make_naming();
};

const Fbs kProfile;
const Registration kRegistration{kProfile};

}  // namespace

}  // namespace plcemu::profiles::fbs
