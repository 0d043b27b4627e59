// The FATEK FB profile, the FBs' predecessor: FATEK's device areas with D0–D3071, FATEK's Modbus
// table without the R3968 remap, the special registers of the FB temperature instructions
// (R3968–R3999 raw readings, R4004–R4023) and its temperature modules (FB manual FUN72/FUN73
// for the FB-2AJ(K)4/FB-2AH(T)4, FUN85/FUN86 for the FB-4AJ(K)xx). docs/profile-fb.md describes it
// for users.

#include "instructions/mov.hpp"
#include "plcemu/profiles/profile.hpp"
#include "profiles/fatek/layout.hpp"
#include "profiles/fatek/listing.hpp"
#include "profiles/fatek/naming.hpp"
#include "profiles/fb/map.hpp"
#include "profiles/fb/model.hpp"
#include "profiles/fb/program_checks.hpp"
#include "profiles/fb/services.hpp"
#include "profiles/fb/special_registers.hpp"
#include "profiles/fb/specials.hpp"
#include "profiles/fb/temperature_config.hpp"
#include "profiles/fb/temperature_modules.hpp"
#include "profiles/fb/tp4.hpp"
#include "profiles/fb/tpctl.hpp"
#include "profiles/fb/tpsns.hpp"
#include "profiles/fb/tstc.hpp"

namespace plcemu::profiles::fb {

namespace {

using image::Area;

// D0–D3071 (FB manual FUN72/FUN73 and FUN86 operand tables; the FBs has D0–D3999).
constexpr std::uint32_t kDataRegisters = 3072;

class Fb final : public Profile {
public:
    std::string_view name() const override { return "fb"; }
    std::string_view title() const override { return "FATEK FB"; }
    std::uint32_t family() const override { return 3; }
    std::string_view vendor() const override { return "FATEK"; }
    std::string_view default_model() const override { return "FB-40MC"; }
    bool valid_model(std::string_view model) const override {
        return model_code(model).has_value();
    }
    std::string_view model_hint() const override { return "an FB model such as FB-40MC"; }
    int max_station() const override { return 254; }
    const image::Naming& naming() const override { return naming_; }

    image::Layout layout() const override {
        return fatek::make_layout(family(), name(), kDataRegisters);
    }

    std::vector<image::Range> always_retentive() const override {
        // R4057 counts starts, whatever the config makes retentive.
        return {{Area::R, special::kPowerUps, 1}};
    }

    std::vector<std::string_view> sections() const override { return {"temperature"}; }
    // Port 0 of every FATEK PLC speaks FATEK's own protocol (FBs manual, chapter 11).
    std::vector<std::string_view> protocols() const override { return {"fatek"}; }
    std::shared_ptr<const config::ProfileSettings> read(const config::Config& config,
                                                        const config::Reader& r) const override {
        const std::size_t before = r.errors_found();
        auto settings = read_settings(config, r);
        // The program against the modules: only once they read cleanly.
        if (r.errors_found() == before)
            r.attempt([&] { check_temperature_program(program_instructions(config)); });
        return settings;
    }

    const modbus::AddressMap& map() const override { return fb::map(); }

    const instructions::Table& instructions() const override {
        static const instructions::Table kTable{
            {"MOV", &instructions::make_mov}, {"TP4", &make_tp4},   {"TPCTL", &make_tpctl},
            {"TPSNS", &make_tpsns},           {"TSTC", &make_tstc},
        };
        return kTable;
    }

    // WinProladder's mnemonic view, with the functions this profile has.
    const instructions::Dialect* listing() const override {
        static const instructions::Dialect kDialect = fatek::listing_dialect({
            {"MOV", 8, {"s", "d"}, true},
            {"TP4", 72, {}, false},
            {"TSTC", 73, {}, false},
            {"TPSNS", 85, {}, false},
            {"TPCTL", 86, {}, false},
        });
        return &kDialect;
    }

    std::unique_ptr<instructions::Services> services(const config::Config& config) const override {
        auto s = std::make_unique<Services>();
        s->timers = fatek::timer_groups();
        s->modules = settings_of(config)->temperature.modules;
        return s;
    }

    // The FB's PID outputs run 0–4095 (FB manual FUN73, OR: "值为 0~4095").
    int drive_full_scale() const override { return 4095; }

    std::unique_ptr<engine::Specials> specials(const config::Config& config) const override {
        return make_specials(model_code(config.model).value_or(0));
    }

    engine::Tags tags(const config::Config& /*config*/,
                      const image::Image& /*image*/) const override {
        return special_tags();
    }

    // The modules sample the plant when a measuring instruction reads a point; point p is
    // plant channel p.
    void attach(engine::Engine& engine,
                const config::Config& /*config*/,
                engine::SensorSource& sensors) const override {
        auto modules = std::make_unique<TemperatureModules>(sensors);
        engine.set_module_bus(modules.get());
        engine.add_subsystem(std::move(modules));
    }

private:
    image::Naming naming_ = fatek::make_naming();
};

const Fb kProfile;
const Registration kRegistration{kProfile};

}  // namespace

}  // namespace plcemu::profiles::fb
