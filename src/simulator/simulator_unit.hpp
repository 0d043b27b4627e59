#pragma once
// The simulator-control unit (docs/simulator-and-plant.md; unit 247 by default): time control,
// plant parameters and fault switches, and read-only plant state, as holding registers on the PLC's
// listeners.

#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "plcemu/engine/time_control.hpp"
#include "plcemu/image/naming.hpp"
#include "plcemu/listener/comm_faults.hpp"
#include "plcemu/modbus/unit.hpp"
#include "plcemu/plant/plant.hpp"

namespace plcemu::simulator {

using plant::kChannels;

/// Wire addresses of the simulator unit's holding registers (docs/simulator-and-plant.md,
/// "Simulator-control unit").
namespace sim {
inline constexpr std::uint16_t kTimeScale = 0;  ///< 1–10000 simulated s per real s
inline constexpr std::uint16_t kFreeze = 1;     ///< 1 = scans stopped
inline constexpr std::uint16_t kStep = 2;       ///< write N: queue N scans; reads the scans queued
inline constexpr std::uint16_t kSimSecondsLo = 3;  ///< simulated seconds, low word (read-only)
inline constexpr std::uint16_t kSimSecondsHi = 4;  ///< simulated seconds, high word (read-only)
/// The communication faults (docs/communication-faults.md, "Simulator unit"), 20-40.
inline constexpr std::uint16_t kCommBase = 20;
/// Offsets in the communication-fault block.
enum CommOffset : std::uint16_t {
    kDelayMin = 0,         ///< delay_ms, or its lower bound: ms, 0-60000
    kDelayMax = 1,         ///< delay_ms's upper bound (below the lower: fixed at the lower)
    kDropEvery = 2,        ///< drop_every N (0: off)
    kDropProbability = 3,  ///< drop_probability in 1/10000, 0-10000
    kSeed = 4,             ///< seed of the delays and drops
    kException = 5,        ///< exception code (0: off)
    kOffline = 6,          ///< 1 = offline
    kRefuse = 7,           ///< 1 = refuse_connections
    kDisconnect = 8,       ///< 0 off, 1 disconnect_after with FIN, 2 with RST (reset)
    kDisconnectAfter = 9,  ///< disconnect_after N (0: at once)
    kGarble = 10,          ///< 0 none, 1 crc, 2 short, 3 gap
    kStop = 11,            ///< 1 = stop (the PLC leaves RUN)
    kScopeUnit = 12,       ///< unit (0: any)
    kScopeFunction = 13,   ///< function (0: any)
    kScopeFrom = 14,       ///< from: a device name, 8 ASCII characters in 4 words, NUL-padded
    kScopeCount = 18,      ///< count (0: 1)
    kClear = 19,           ///< write 1: every fault off (reads 0)
    kCommStatus = 20,      ///< read-only: b0 a fault is on, b1 the last write was refused
};
inline constexpr std::uint16_t kCommEnd = kCommBase + kCommStatus + 1;  ///< 41
inline constexpr std::uint16_t kChannelBase = 100;   ///< channel c at 100 + 10·c
inline constexpr std::uint16_t kChannelStride = 10;  ///< words per channel block
/// Offsets in a channel block.
enum Offset : std::uint16_t {
    kFaults = 0,       ///< b0 sensor broken, b1 heater open, b2 heater shorted, b3 reading frozen
    kAmbient = 1,      ///< 0.1 °C, signed
    kGain = 2,         ///< K, 0.1 °C
    kTau = 3,          ///< τ, s
    kDeadTime = 4,     ///< θ, s
    kNoise = 5,        ///< σ, 0.01 °C
    kTrueTemp = 6,     ///< 0.1 °C, signed, read-only
    kHeaterPower = 7,  ///< 0.1 %, read-only
    kLeadResistance = 8,  ///< an RTD's lead resistance, 0.01 Ω, 0–10000
};
inline constexpr std::uint16_t kEnd = kChannelBase + kChannelStride * kChannels;  ///< 420
}  // namespace sim

/// One register of the unit as the tag export lists it.
struct RegisterTag {
    std::uint16_t wire = 0;   ///< holding register address
    std::string name;         ///< "sim.time_scale", "sim.ch3.ambient"
    std::string description;  ///< what it holds, with its unit
    bool is_signed = false;   ///< a signed value (ambient, true temperature)
};

/// Every register of the unit (the channel words of all kChannels channels, not the reserved
/// ones); SimulatorUnit::writable says which a master may write.
std::vector<RegisterTag> register_tags();

/// The unit. Reads show the live state; writes are applied after they land, clamped to the
/// ranges of the table (the reply is already on the wire, so no exception 03 is possible).
class SimulatorUnit final : public modbus::Unit {
public:
    /// `plant` and `time` must outlive the unit, and `faults` and `naming` (its device names,
    /// for the faults' scope) when given. Not `writable`: every write is refused with
    /// exception 02, as the PLC's registers are under modbus.read_only.
    SimulatorUnit(plant::Plant& plant,
                  engine::TimeControl& time,
                  bool writable = true,
                  listener::CommFaults* faults = nullptr,
                  const image::Naming* naming = nullptr);

    modbus::Window resolve(modbus::Table table,
                           std::uint16_t addr,
                           std::uint16_t qty,
                           bool write) noexcept override;
    void written(modbus::Table table, std::uint16_t addr, std::uint16_t qty) noexcept override;
    /// The holding-register functions (03, 06, 16, 22, 23) only: the unit is no PLC, and
    /// answering the identity requests (08, 11h, 2Bh) would list it as one beside the station.
    bool serves(std::uint8_t fc) const noexcept override;

    /// True for a wire address of the map (read access).
    static bool mapped(std::uint16_t addr);
    /// True for a wire address a master may write.
    static bool writable(std::uint16_t addr);

private:
    void refresh() noexcept;
    void refresh_comm_faults() noexcept;
    void apply(std::uint16_t addr, std::uint16_t v) noexcept;
    void apply_comm_faults(bool clear) noexcept;

    plant::Plant& plant_;
    engine::TimeControl& time_;
    bool writable_;
    listener::CommFaults* faults_;
    const image::Naming* naming_;
    bool comm_refused_ = false;  // the last write to the fault block was refused
    std::array<std::uint16_t, sim::kEnd> regs_{};
};

}  // namespace plcemu::simulator
