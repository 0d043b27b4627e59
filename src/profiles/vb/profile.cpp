// The VIGOR VB profile: the FX2N-style device areas with X/Y in octal, the special devices moved
// to M9000/D9000, a Modbus slave map after the FX3U default allocation, its temperature modules
// and the program entries of the VB manual's examples (docs/profile-vb.md describes it for users).

#include <chrono>

#include "instructions/cmp.hpp"
#include "instructions/cmpout.hpp"
#include "instructions/cnt.hpp"
#include "instructions/from_to.hpp"
#include "instructions/mov.hpp"
#include "instructions/pls.hpp"
#include "instructions/rst.hpp"
#include "instructions/tmr.hpp"
#include "instructions/wor.hpp"
#include "plcemu/profiles/profile.hpp"
#include "profiles/vb/hour.hpp"
#include "profiles/vb/listing.hpp"
#include "profiles/vb/map.hpp"
#include "profiles/vb/mbus.hpp"
#include "profiles/vb/model.hpp"
#include "profiles/vb/operation_error.hpp"
#include "profiles/vb/pid.hpp"
#include "profiles/vb/services.hpp"
#include "profiles/vb/settings.hpp"
#include "profiles/vb/specials.hpp"
#include "profiles/vb/temperature_modules.hpp"
#include "profiles/vb/tpid.hpp"

namespace plcemu::profiles::vb {

namespace {

using image::Area;

image::Naming make_naming() {
    image::Naming n;
    // Longest prefixes first so that "TN"/"TS" win over "T" and "CN"/"CS" over "C".
    n.prefixes = {{"TN", Area::TV}, {"CN", Area::CV}, {"TS", Area::T}, {"CS", Area::C},
                  {"X", Area::X},   {"Y", Area::Y},   {"M", Area::M},  {"S", Area::S},
                  {"T", Area::T},   {"C", Area::C},   {"D", Area::D}};
    // No R: the area does not exist on a VB.
    n.names = {"X", "Y", "M", "S", "T", "C", "", "D", "TN", "CN"};
    n.radix.fill(10);
    // X0–X377, Y0–Y377 (VB manual FNC92, example II: "Y0…Y7, Y10…Y17").
    n.radix[static_cast<std::size_t>(Area::X)] = 8;
    n.radix[static_cast<std::size_t>(Area::Y)] = 8;
    // C200–C255 are 32-bit: two words each, low word first.
    n.first_32bit_counter = 200;
    // The manual writes constants as K100 and H0011 (VB manual FNC88, example).
    n.hex_prefix_h = true;
    return n;
}

class Vb final : public Profile {
public:
    std::string_view name() const override { return "vb"; }
    std::string_view title() const override { return "VIGOR VB"; }
    std::uint32_t family() const override { return 2; }
    std::string_view vendor() const override { return "VIGOR"; }
    std::string_view default_model() const override { return "VB2-32M"; }
    bool valid_model(std::string_view model) const override { return vb::valid_model(model); }
    std::string_view model_hint() const override {
        return "a VIGOR model such as VB2-32M or VH-40MR";
    }
    int max_station() const override { return 247; }
    const image::Naming& naming() const override { return naming_; }

    image::Layout layout() const override {
        image::Layout l;
        l.family = family();
        l.family_name = name();
        l.set_size(Area::X, 256);
        l.set_size(Area::Y, 256);
        // M0–M3071 and M9000–M9255 in one array so that numbers equal indices.
        l.set_size(Area::M, 9256);
        l.set_size(Area::S, 1000);
        l.set_size(Area::T, 256);
        l.set_size(Area::C, 256);
        l.set_size(Area::D, 9256);
        l.set_size(Area::TV, 256);
        // C0–C199 one word each, C200–C255 two words each (low word first).
        l.set_size(Area::CV, 200 + 56 * 2);
        l.holes = {{Area::M, 3072, 9000 - 3072}, {Area::D, 8000, 9000 - 8000}};
        // FX2N's latched ranges (docs/profile-vb.md, "Device areas").
        l.retentive = {
            {Area::M, 500, 3072 - 500},
            {Area::S, 500, 500},
            {Area::T, 246, 10},
            {Area::TV, 246, 10},
            {Area::C, 100, 100},
            {Area::CV, 100, 100},
            {Area::C, 220, 36},
            {Area::CV, naming_.counter_word(220), 36 * 2},  // C220–C255, two words each
            {Area::D, 200, 8000 - 200},
        };
        return l;
    }

    const modbus::AddressMap& map() const override { return vb::map(); }

    const instructions::Table& instructions() const override {
        static const instructions::Table kTable{
            {"CMP", &instructions::make_cmp},
            {"CMPOUT", &instructions::make_cmpout},
            {"CNT", &instructions::make_cnt},
            {"DHOUR", &make_dhour},
            {"FROM", &instructions::make_from},
            {"HOUR", &make_hour},
            {"MBUS", &make_mbus},
            {"MOV", &instructions::make_mov},
            {"PID", &make_pid},
            {"PLS", &instructions::make_pls},
            {"RST", &instructions::make_rst},
            {"TMR", &instructions::make_tmr},
            {"TO", &instructions::make_to},
            {"TPID", &make_tpid},
            {"WOR", &instructions::make_wor},
            {"ZRST", &instructions::make_zrst},
        };
        return kTable;
    }

    const instructions::Dialect* listing() const override { return &listing_dialect(); }

    std::unique_ptr<instructions::Services> services(const config::Config& config) const override {
        auto s = std::make_unique<Services>();
        for (const auto& r : program_data(config)) {
            s->reserved_outputs.emplace_back(
                r, "the file registers (file_registers:), program data the program only reads");
        }
        // M9200–M9234: count direction of C200–C234 (FX M8200–M8234); C235–C255 have none here
        // (docs/profile-vb.md).
        s->direction = {Area::M, special::kCountDown, special::kCountDownRelays};
        s->operation_error = kOperationError;
        // The FX2N timers (docs/profile-vb.md, "Device areas"): T0–T199 100 ms, T200–T245 10 ms,
        // T246–T249 1 ms retentive, T250–T255 100 ms retentive.
        using std::chrono::milliseconds;
        s->timers = {{0, 200, milliseconds(100), false},
                     {200, 46, milliseconds(10), false},
                     {246, 4, milliseconds(1), true},
                     {250, 6, milliseconds(100), true}};
        return s;
    }

    std::unique_ptr<engine::Specials> specials(const config::Config& /*config*/) const override {
        return make_specials();
    }

    std::vector<std::string_view> sections() const override {
        return {"modules", "mbus", "file_registers"};
    }
    std::shared_ptr<const config::ProfileSettings> read(const config::Config& config,
                                                        const config::Reader& r) const override {
        return read_settings(config, r);
    }

    std::vector<image::Range> program_data(const config::Config& config) const override {
        const auto r = settings_of(config)->file_registers;
        return r ? std::vector<image::Range>{*r} : std::vector<image::Range>{};
    }

    engine::Tags tags(const config::Config& config, const image::Image& /*image*/) const override {
        engine::Tags t = special_tags();
        for (const auto& r : program_data(config)) {
            t.push_back({r, "file register: program data from file_registers:, read-only"});
        }
        return t;
    }

    // The TPID's analog outputs run 0–1000 (VB manual FNC92, S3+10m).
    int drive_full_scale() const override { return 1000; }

    // The temperature modules sample the plant before the program reads them with FROM.
    void attach(engine::Engine& engine,
                const config::Config& config,
                engine::SensorSource& sensors) const override {
        const auto settings = settings_of(config);
        if (settings->modules.empty()) return;
        auto bus = std::make_unique<TemperatureModules>(settings->modules, sensors);
        engine.set_module_bus(bus.get());
        engine.add_subsystem(std::move(bus));
    }

    // FNC149 MBUS polls its slaves through the CP2 port `mbus:` describes.
    std::optional<config::MasterConfig> master(const config::Config& config) const override {
        return settings_of(config)->mbus;
    }

private:
    image::Naming naming_ = make_naming();
};

const Vb kProfile;
const Registration kRegistration{kProfile};

}  // namespace

}  // namespace plcemu::profiles::vb
