#pragma once
// A VB program scanned in virtual time, on its own or in a closed loop with the thermal plant
// (channel 0): the PV register gets round(T·10) before the program, as a temperature module
// reads 0.1 °C, and the plant is driven by the MV register scaled to a full-scale value.

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>

#include "plcemu/config/config.hpp"
#include "plcemu/daemon/plc.hpp"
#include "plcemu/image/image.hpp"
#include "plcemu/plant/plant.hpp"
#include "support/profiles.hpp"

namespace plcemu::testing {

class VbRig {
public:
    /// `program`: the YAML list entries under `program:`, one per line.
    explicit VbRig(const std::string& program, engine::Duration dt = std::chrono::milliseconds(10))
        : cfg_(config::parse_config("profile: vb\nprogram:\n" + program, "vb_rig.yaml")),
          img_(profile("vb").layout()),
          prog_(daemon::build_program(cfg_)),
          dt_(dt) {}

    /// D register i (raw word).
    std::uint16_t& d(std::uint32_t i) { return img_.words(image::Area::D)[i]; }
    /// D register i as the signed value the VB holds.
    int sd(std::uint32_t i) { return static_cast<std::int16_t>(d(i)); }
    /// Writes a signed value into D register i.
    void set(std::uint32_t i, int v) { d(i) = static_cast<std::uint16_t>(v); }
    bool m(std::uint32_t i) const { return img_.bit(image::Area::M, i); }
    void set_m(std::uint32_t i, bool v) { img_.set_bit(image::Area::M, i, v); }
    image::Image& image() { return img_; }

    /// Closes the loop through plant channel 0 (the default plant: K 400 °C, τ 120 s, θ 5 s,
    /// 25 °C): D`pv` reads the temperature, D`mv` drives the heater with `full_scale` = 100 %.
    /// The drive goes through D`scratch`, scaled to the plant's register full scale, 16383.
    void close_loop(std::uint32_t pv, std::uint32_t mv, int full_scale, std::uint32_t scratch) {
        plant::PlantSetup setup;
        setup.channels[0].drive = {plant::Drive::Kind::Register,
                                   image::Device{image::Area::D, scratch, false}};
        plant_ = plant::make_plant(setup);
        loop_ = Loop{pv, mv, full_scale, scratch};
    }
    plant::Plant& plant() { return *plant_; }
    /// The true temperature of channel 0, °C.
    double temperature() const { return plant_->true_temperature(0); }

    void scan(int n = 1) {
        for (int k = 0; k < n; ++k) {
            engine::ScanContext ctx{img_, now_, dt_, scans_, scans_ == 0};
            if (plant_) {
                plant_->inputs(ctx);
                set(loop_->pv, static_cast<int>(std::lround(temperature() * 10.0)));
            }
            for (auto& i : prog_) i->execute(ctx);
            if (plant_) {
                const double u = std::clamp(sd(loop_->mv), 0, loop_->full_scale);
                set(loop_->scratch, static_cast<int>(std::lround(u * 16383.0 / loop_->full_scale)));
                plant_->outputs(ctx);
            }
            now_ += dt_;
            ++scans_;
        }
    }
    /// Scans until `t` of simulated time has passed.
    void run_for(engine::Duration t) { scan(static_cast<int>(t / dt_)); }
    /// Simulated time of the next scan.
    engine::Duration now() const { return now_; }
    double seconds() const { return std::chrono::duration<double>(now_).count(); }
    engine::Duration dt() const { return dt_; }

private:
    struct Loop {
        std::uint32_t pv;
        std::uint32_t mv;
        int full_scale;
        std::uint32_t scratch;
    };

    config::Config cfg_;
    image::Image img_;
    engine::Program prog_;
    engine::Duration dt_;
    engine::Duration now_{0};
    std::uint64_t scans_ = 0;
    std::unique_ptr<plant::Plant> plant_;
    std::optional<Loop> loop_;
};

}  // namespace plcemu::testing
