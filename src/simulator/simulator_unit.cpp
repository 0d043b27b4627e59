#include "simulator/simulator_unit.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>

namespace plcemu::simulator {

using plant::ChannelParams;
using plant::Faults;

namespace {

using modbus::Status;
using modbus::Table;
using modbus::Window;

std::uint16_t unsigned_word(double v) {
    return static_cast<std::uint16_t>(std::lround(std::clamp(v, 0.0, 65535.0)));
}

std::uint16_t signed_word(double v) {
    const long x = std::lround(std::clamp(v, -32768.0, 32767.0));
    return static_cast<std::uint16_t>(static_cast<std::int16_t>(x));
}

std::uint16_t fault_bits(const Faults& f) {
    return static_cast<std::uint16_t>((f.sensor_broken ? 1u : 0u) | (f.heater_open ? 2u : 0u) |
                                      (f.heater_shorted ? 4u : 0u) | (f.reading_frozen ? 8u : 0u));
}

}  // namespace

SimulatorUnit::SimulatorUnit(plant::Plant& plant, engine::TimeControl& time, bool writable)
    : plant_(plant),
      time_(time),
      writable_(writable) {
    refresh();
}

std::vector<RegisterTag> register_tags() {
    std::vector<RegisterTag> t{
        {sim::kTimeScale, "sim.time_scale",
         "simulator: time scale, 1-10000 simulated s per real s"},
        {sim::kFreeze, "sim.freeze", "simulator: freeze, 1 = scans stopped"},
        {sim::kStep, "sim.step", "simulator: step, write N to run N scans; reads the scans queued"},
        {sim::kSimSecondsLo, "sim.time_low", "simulator: simulated time, s, low word"},
        {sim::kSimSecondsHi, "sim.time_high", "simulator: simulated time, s, high word"},
    };
    struct Field {
        sim::Offset offset;
        const char* name;
        const char* what;
        bool is_signed;
    };
    static constexpr Field kFields[] = {
        {sim::kFaults, "faults",
         "faults: b0 sensor broken, b1 heater open, b2 heater shorted, b3 reading frozen", false},
        {sim::kAmbient, "ambient", "ambient, 0.1 C", true},
        {sim::kGain, "k", "K full-power rise, 0.1 C", false},
        {sim::kTau, "tau", "tau, s", false},
        {sim::kDeadTime, "dead_time", "dead time, s", false},
        {sim::kNoise, "noise", "noise sigma, 0.01 C", false},
        {sim::kTrueTemp, "true_temperature", "true temperature, 0.1 C", true},
        {sim::kHeaterPower, "heater_power", "heater power, 0.1 % (mean of the last 8 s)", false},
    };
    for (int c = 0; c < kChannels; ++c) {
        const std::string ch = "ch" + std::to_string(c);
        for (const auto& f : kFields) {
            t.push_back(
                {static_cast<std::uint16_t>(sim::kChannelBase + sim::kChannelStride * c + f.offset),
                 "sim." + ch + "." + f.name,
                 "simulator: channel " + std::to_string(c) + " " + f.what, f.is_signed});
        }
    }
    return t;
}

bool SimulatorUnit::mapped(std::uint16_t addr) {
    return addr <= sim::kSimSecondsHi || (addr >= sim::kChannelBase && addr < sim::kEnd);
}

bool SimulatorUnit::writable(std::uint16_t addr) {
    if (addr <= sim::kStep) return true;
    if (addr < sim::kChannelBase || addr >= sim::kEnd) return false;
    const int off = (addr - sim::kChannelBase) % sim::kChannelStride;
    return off <= sim::kNoise || off == sim::kLeadResistance;
}

void SimulatorUnit::refresh() noexcept {
    const double scale = std::round(time_.time_scale());
    regs_[sim::kTimeScale] = static_cast<std::uint16_t>(std::clamp(scale, 1.0, 10000.0));
    regs_[sim::kFreeze] = time_.frozen() ? 1 : 0;
    // Reads the scans still queued: a client polls it for 0 to know its steps have run.
    regs_[sim::kStep] =
        static_cast<std::uint16_t>(std::min<std::uint64_t>(time_.pending_steps(), 0xFFFF));
    const auto secs = static_cast<std::uint32_t>(
        std::chrono::duration_cast<std::chrono::seconds>(time_.simulated_time()).count());
    regs_[sim::kSimSecondsLo] = static_cast<std::uint16_t>(secs & 0xFFFF);
    regs_[sim::kSimSecondsHi] = static_cast<std::uint16_t>(secs >> 16);
    for (int c = 0; c < kChannels; ++c) {
        std::uint16_t* w =
            regs_.data() + sim::kChannelBase + std::ptrdiff_t{sim::kChannelStride} * c;
        const ChannelParams& p = plant_.params(c);
        w[sim::kFaults] = fault_bits(plant_.faults(c));
        w[sim::kAmbient] = signed_word(p.ambient_c * 10.0);
        w[sim::kGain] = unsigned_word(p.k_c * 10.0);
        w[sim::kTau] = std::max<std::uint16_t>(1, unsigned_word(p.tau_s));
        w[sim::kDeadTime] = unsigned_word(p.dead_time_s);
        w[sim::kNoise] = unsigned_word(p.noise_c * 100.0);
        w[sim::kTrueTemp] = signed_word(plant_.true_temperature(c) * 10.0);
        w[sim::kHeaterPower] = unsigned_word(plant_.heater_power(c) * 1000.0);
        w[sim::kLeadResistance] = unsigned_word(p.lead_ohm * 100.0);
        w[9] = 0;  // reserved
    }
}

Window SimulatorUnit::resolve(Table table,
                              std::uint16_t addr,
                              std::uint16_t qty,
                              bool write) noexcept {
    Window w;
    if (table != Table::HoldingRegisters) {
        w.status = Status::IllegalFunction;
        return w;
    }
    if (write && !writable_) return w;
    const std::uint32_t end = std::uint32_t{addr} + qty;
    for (std::uint32_t a = addr; a < end; ++a) {
        const auto x = static_cast<std::uint16_t>(a);
        // Any unmapped word, or a read-only one in a write, refuses the whole request.
        if (a >= sim::kEnd || !mapped(x) || (write && !writable(x))) return w;
    }
    refresh();
    w.status = Status::Ok;
    w.words = regs_.data() + addr;
    return w;
}

void SimulatorUnit::apply(std::uint16_t addr, std::uint16_t v) noexcept {
    if (addr == sim::kTimeScale) {
        time_.set_time_scale(std::clamp<double>(v, 1.0, 10000.0));
        return;
    }
    if (addr == sim::kFreeze) {
        time_.set_frozen(v != 0);
        return;
    }
    if (addr == sim::kStep) {
        // 0 cancels what is still queued.
        if (v > 0) {
            time_.step(v);
        } else {
            time_.cancel_steps();
        }
        return;
    }
    const int c = (addr - sim::kChannelBase) / sim::kChannelStride;
    const int off = (addr - sim::kChannelBase) % sim::kChannelStride;
    if (off == sim::kFaults) {
        Faults f;
        f.sensor_broken = (v & 1u) != 0;
        f.heater_open = (v & 2u) != 0;
        f.heater_shorted = (v & 4u) != 0;
        f.reading_frozen = (v & 8u) != 0;
        plant_.set_faults(c, f);
        return;
    }
    ChannelParams p = plant_.params(c);
    switch (off) {
        case sim::kAmbient:
            p.ambient_c = static_cast<std::int16_t>(v) / 10.0;
            break;
        case sim::kGain:
            p.k_c = v / 10.0;
            break;
        case sim::kTau:
            p.tau_s = std::max<double>(1.0, v);
            break;
        case sim::kDeadTime:
            p.dead_time_s = v;
            break;
        case sim::kNoise:
            p.noise_c = v / 100.0;
            break;
        case sim::kLeadResistance:
            p.lead_ohm = v / 100.0;
            break;
        default:
            return;
    }
    plant_.set_params(c, p);  // clamps to the model's ranges
}

void SimulatorUnit::written(Table table, std::uint16_t addr, std::uint16_t qty) noexcept {
    if (table != Table::HoldingRegisters) return;
    // In address order, so one write of [freeze = 1, step = N] freezes and then steps.
    const std::uint32_t end = std::min<std::uint32_t>(std::uint32_t{addr} + qty, sim::kEnd);
    for (std::uint32_t a = addr; a < end; ++a) {
        apply(static_cast<std::uint16_t>(a), regs_[a]);
    }
    refresh();
}

}  // namespace plcemu::simulator
