#include "simulator/simulator_unit.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <string>
#include <string_view>

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

SimulatorUnit::SimulatorUnit(plant::Plant& plant,
                             engine::TimeControl& time,
                             bool writable,
                             listener::CommFaults* faults,
                             const image::Naming* naming)
    : plant_(plant),
      time_(time),
      writable_(writable),
      faults_(faults),
      naming_(naming) {
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
    static constexpr struct {
        sim::CommOffset offset;
        const char* name;
        const char* what;
    } kComm[] = {
        {sim::kDelayMin, "delay_min_ms", "delay_ms, or its lower bound, ms"},
        {sim::kDelayMax, "delay_max_ms", "delay_ms upper bound, ms (below the lower: fixed)"},
        {sim::kDropEvery, "drop_every", "drop every Nth request (0 off)"},
        {sim::kDropProbability, "drop_probability", "drop probability, 1/10000"},
        {sim::kSeed, "seed", "seed of delays and drops"},
        {sim::kException, "exception", "exception code (0 off)"},
        {sim::kOffline, "offline", "offline, 1 = on"},
        {sim::kRefuse, "refuse_connections", "refuse new TCP connections, 1 = on"},
        {sim::kDisconnect, "disconnect", "disconnect: 0 off, 1 FIN, 2 RST"},
        {sim::kDisconnectAfter, "disconnect_after", "disconnect after N requests (0 at once)"},
        {sim::kGarble, "garble", "garble: 0 none, 1 crc, 2 short, 3 gap"},
        {sim::kStop, "stop", "stop, 1 = the PLC leaves RUN"},
        {sim::kScopeUnit, "unit", "scope: unit ID (0 any)"},
        {sim::kScopeFunction, "function", "scope: function code (0 any)"},
        {sim::kScopeFrom, "from_1", "scope: from, characters 1-2 (ASCII)"},
        {static_cast<sim::CommOffset>(sim::kScopeFrom + 1), "from_2",
         "scope: from, characters 3-4"},
        {static_cast<sim::CommOffset>(sim::kScopeFrom + 2), "from_3",
         "scope: from, characters 5-6"},
        {static_cast<sim::CommOffset>(sim::kScopeFrom + 3), "from_4",
         "scope: from, characters 7-8"},
        {sim::kScopeCount, "count", "scope: count of devices from `from` (0: 1)"},
        {sim::kClear, "clear", "write 1: every communication fault off"},
        {sim::kCommStatus, "status", "b0 a fault is on, b1 the last write was refused"},
    };
    for (const auto& f : kComm) {
        t.push_back({static_cast<std::uint16_t>(sim::kCommBase + f.offset),
                     std::string("sim.comm.") + f.name,
                     std::string("simulator: comm.") + f.name + ": communication fault " + f.what,
                     false});
    }
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
    return addr <= sim::kSimSecondsHi || (addr >= sim::kCommBase && addr < sim::kCommEnd) ||
           (addr >= sim::kChannelBase && addr < sim::kEnd);
}

bool SimulatorUnit::writable(std::uint16_t addr) {
    if (addr <= sim::kStep) return true;
    if (addr >= sim::kCommBase && addr < sim::kCommEnd)
        return addr != sim::kCommBase + sim::kCommStatus;
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
    refresh_comm_faults();
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

void SimulatorUnit::refresh_comm_faults() noexcept {
    std::uint16_t* w = regs_.data() + sim::kCommBase;
    std::fill(w, w + (sim::kCommEnd - sim::kCommBase), std::uint16_t{0});
    w[sim::kCommStatus] = comm_refused_ ? 2 : 0;
    if (faults_ == nullptr) return;
    const config::CommFaultSettings& f = faults_->settings();
    w[sim::kDelayMin] = static_cast<std::uint16_t>(f.delay_min_ms);
    w[sim::kDelayMax] = static_cast<std::uint16_t>(f.delay_max_ms);
    w[sim::kDropEvery] = static_cast<std::uint16_t>(f.drop_every);
    w[sim::kDropProbability] = unsigned_word(f.drop_probability * 10000.0);
    w[sim::kSeed] = static_cast<std::uint16_t>(f.seed);
    w[sim::kException] = f.exception;
    w[sim::kOffline] = f.offline ? 1 : 0;
    w[sim::kRefuse] = f.refuse_connections ? 1 : 0;
    w[sim::kDisconnect] = !f.disconnect_after ? 0 : f.reset ? 2 : 1;
    w[sim::kDisconnectAfter] = static_cast<std::uint16_t>(f.disconnect_after.value_or(0));
    w[sim::kGarble] = static_cast<std::uint16_t>(f.garble);
    w[sim::kStop] = f.stop ? 1 : 0;
    w[sim::kScopeUnit] = f.unit;
    w[sim::kScopeFunction] = f.function;
    if (f.devices && naming_ != nullptr) {
        // The first device's name, two characters a word, high byte first.
        const std::string name = naming_->format_device(f.devices->area, f.devices->start);
        for (std::size_t i = 0; i < name.size() && i < 8; ++i) {
            const auto c = static_cast<std::uint8_t>(name[i]);
            std::uint16_t& word = w[sim::kScopeFrom + i / 2];
            word = static_cast<std::uint16_t>(word | (i % 2 == 0 ? c << 8 : c));
        }
        w[sim::kScopeCount] = static_cast<std::uint16_t>(
            std::min<std::uint32_t>(naming_->devices_in(*f.devices), 0xFFFF));
    }
    if (faults_->active())
        w[sim::kCommStatus] = static_cast<std::uint16_t>(w[sim::kCommStatus] | 1u);
}

void SimulatorUnit::apply_comm_faults(bool clear) noexcept {
    if (faults_ == nullptr) return;
    if (clear) {
        comm_refused_ = false;
        faults_->clear();
        return;
    }
    const std::uint16_t* w = regs_.data() + sim::kCommBase;
    config::CommFaultSettings s;
    // Clamped to the table's ranges, as every register of the unit is: the reply is already
    // on the wire. What cannot be clamped (a name that is no device) refuses the whole write.
    s.delay_min_ms = std::min<std::uint32_t>(w[sim::kDelayMin], config::kMaxCommDelayMs);
    s.delay_max_ms = std::max(s.delay_min_ms,
                              std::min<std::uint32_t>(w[sim::kDelayMax], config::kMaxCommDelayMs));
    if (w[sim::kDelayMax] < w[sim::kDelayMin]) s.delay_max_ms = s.delay_min_ms;
    s.drop_every = w[sim::kDropEvery];
    s.drop_probability = std::min<double>(w[sim::kDropProbability], 10000) / 10000.0;
    s.seed = w[sim::kSeed];
    s.exception = static_cast<std::uint8_t>(std::min<std::uint16_t>(w[sim::kException], 255));
    s.offline = w[sim::kOffline] != 0;
    s.refuse_connections = w[sim::kRefuse] != 0;
    if (w[sim::kDisconnect] != 0) {
        s.disconnect_after = w[sim::kDisconnectAfter];
        s.reset = w[sim::kDisconnect] >= 2;
    }
    s.garble = static_cast<config::Garble>(
        std::min<std::uint16_t>(w[sim::kGarble], static_cast<std::uint16_t>(config::Garble::Gap)));
    s.stop = w[sim::kStop] != 0;
    s.unit = static_cast<std::uint8_t>(std::min<std::uint16_t>(w[sim::kScopeUnit], 255));
    s.function = static_cast<std::uint8_t>(std::min<std::uint16_t>(w[sim::kScopeFunction], 255));
    std::string from;
    for (int i = 0; i < 8; ++i) {
        const std::uint16_t word = w[sim::kScopeFrom + i / 2];
        from += static_cast<char>(i % 2 == 0 ? word >> 8 : word & 0xFF);
    }
    // Padded with spaces or NULs at either end; anything between (a space in "R 1", a NUL in
    // "R1\0R2") makes it no device name, and the write is refused.
    constexpr std::string_view kPad(" \0", 2);
    const auto first = from.find_first_not_of(kPad);
    from = first == std::string::npos ? std::string()
                                      : from.substr(first, from.find_last_not_of(kPad) + 1 - first);
    comm_refused_ = false;
    if (!from.empty()) {
        const std::uint32_t count = std::max<std::uint32_t>(w[sim::kScopeCount], 1);
        s.devices =
            naming_ != nullptr ? config::comm_fault_range(*naming_, from, count) : std::nullopt;
        if (!s.devices) {
            comm_refused_ = true;
            return;
        }
    }
    if (!faults_->refusal(s).empty()) {
        comm_refused_ = true;
        return;
    }
    faults_->set(s);
}

void SimulatorUnit::apply(std::uint16_t addr, std::uint16_t v) noexcept {
    if (addr >= sim::kCommBase && addr < sim::kCommEnd) return;  // the block goes as one
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

bool SimulatorUnit::serves(std::uint8_t fc) const noexcept {
    return fc == 0x03 || fc == 0x06 || fc == 0x10 || fc == 0x16 || fc == 0x17;
}

void SimulatorUnit::written(Table table, std::uint16_t addr, std::uint16_t qty) noexcept {
    if (table != Table::HoldingRegisters) return;
    // In address order, so one write of [freeze = 1, step = N] freezes and then steps.
    const std::uint32_t end = std::min<std::uint32_t>(std::uint32_t{addr} + qty, sim::kEnd);
    for (std::uint32_t a = addr; a < end; ++a) {
        apply(static_cast<std::uint16_t>(a), regs_[a]);
    }
    // The fault block as one: a write of several of its words switches once, logged once.
    if (addr < sim::kCommEnd && end > sim::kCommBase) {
        const std::uint16_t clear = sim::kCommBase + sim::kClear;
        apply_comm_faults(addr <= clear && clear < end && regs_[clear] != 0);
    }
    refresh();
}

}  // namespace plcemu::simulator
