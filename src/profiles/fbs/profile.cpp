// The FATEK FBs profile: the device areas and retentive ranges of the FBs manual, its Modbus
// table (13-50/51), the special relays and registers, the A556h temperature measurement and
// FUN86 TPCTL (FBs manual §21.3, §21.7). docs/profile-fbs.md describes it for users.

#include "instructions/mov.hpp"
#include "plcemu/profiles/profile.hpp"
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

image::Naming make_naming() {
    image::Naming n;
    // Longest prefixes first so that "TMR" wins over "T" and "CTR" over "C".
    n.prefixes = {{"TMR", Area::TV}, {"CTR", Area::CV}, {"X", Area::X}, {"Y", Area::Y},
                  {"M", Area::M},    {"S", Area::S},    {"T", Area::T}, {"C", Area::C},
                  {"R", Area::R},    {"D", Area::D}};
    n.names = {"X", "Y", "M", "S", "T", "C", "R", "D", "TMR", "CTR"};
    n.radix.fill(10);
    // C0–C199 take one word each, C200–C255 two (low word first).
    n.first_32bit_counter = 200;
    return n;
}

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

    image::Layout layout() const override {
        image::Layout l;
        l.family = family();
        l.family_name = name();
        l.set_size(Area::X, 256);
        l.set_size(Area::Y, 256);
        l.set_size(Area::M, 2002);
        l.set_size(Area::S, 1000);
        l.set_size(Area::T, 256);
        l.set_size(Area::C, 256);
        // R0–R8071 as one array: R4168–R4999 exist on no FBs and are never mapped, but one
        // array keeps the R numbers equal to indices.
        l.set_size(Area::R, 8072);
        l.set_size(Area::D, 4000);
        l.set_size(Area::TV, 256);
        // C0–C199 one word each, C200–C255 two words each (low word first).
        l.set_size(Area::CV, 200 + 56 * 2);
        // The FBs manual's default retentive ranges (docs/profile-fbs.md).
        l.retentive = {
            {Area::M, 800, 600},
            {Area::S, 500, 500},
            {Area::R, 0, 3000},
            {Area::D, 0, 4000},
            {Area::R, 5000, 3072},
            {Area::CV, 100, 40},
            {Area::CV, 200, 80},  // C200–C239, two words each
            {Area::R, special::kPowerUps, 1},
        };
        return l;
    }

    std::vector<image::Range> always_retentive() const override {
        // R4057 counts starts, whatever the config makes retentive.
        return {{Area::R, special::kPowerUps, 1}};
    }

    std::vector<std::string_view> sections() const override { return {"temperature"}; }
    void check(const config::Config& config) const override { temperature_config(config); }

    const modbus::AddressMap& map() const override { return fbs::map(); }

    const instructions::Table& instructions() const override {
        static const instructions::Table kTable{
            {"MOV", &instructions::make_mov},
            {"TPCTL", &make_tpctl},
        };
        return kTable;
    }

    std::unique_ptr<instructions::Services> services(const config::Config& config) const override {
        auto s = std::make_unique<Services>();
        s->temperature_table = temperature_config(config).table;
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
        if (temperature_config(config).table)
            engine.add_subsystem(make_temperature_table(config, sensors));
    }

private:
    image::Naming naming_ = make_naming();
};

const Fbs kProfile;
const Registration kRegistration{kProfile};

}  // namespace

}  // namespace plcemu::profiles::fbs
