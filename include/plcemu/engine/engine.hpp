#pragma once
// The scan-cycle engine: one scan is a pure function of the image, the plant and `now`.

#include <chrono>
#include <cstdint>
#include <memory>
#include <optional>
#include <string_view>
#include <vector>

#include "plcemu/engine/declarations.hpp"
#include "plcemu/engine/holds.hpp"
#include "plcemu/engine/modules.hpp"
#include "plcemu/engine/outbound.hpp"
#include "plcemu/engine/specials.hpp"
#include "plcemu/engine/loops.hpp"
#include "plcemu/engine/tags.hpp"
#include "plcemu/image/image.hpp"

namespace plcemu::engine {

/// Simulated time since power-up.
using Duration = std::chrono::nanoseconds;

/// Wall-clock date and time for the calendar registers, passed in by whoever owns a clock.
struct Calendar {
    int second = 0;   ///< 0–59
    int minute = 0;   ///< 0–59
    int hour = 0;     ///< 0–23
    int day = 1;      ///< 1–31
    int month = 1;    ///< 1–12
    int year = 2026;  ///< four digits (the register holds the last two)
    int weekday = 0;  ///< 0 = Sunday
};

/// What an instruction sees during one scan.
struct ScanContext {
    image::Image& image;               ///< the register image
    Duration now;                      ///< simulated time of this scan's start
    Duration dt;                       ///< simulated time since the previous scan (the scan period)
    std::uint64_t scan;                ///< scans completed before this one
    bool first_scan;                   ///< the first scan after a power-up, a reload or STOP->RUN
    ModuleBus* modules = nullptr;      ///< the special modules (null: the PLC has none)
    OutboundLink* outbound = nullptr;  ///< the Modbus master port (null: none attached)
    bool running = true;               ///< RUN (true) or STOP: the program runs only in RUN
};

/// One program instruction (one file per mnemonic in src/instructions).
class Instruction {
public:
    virtual ~Instruction() = default;
    /// Runs once per scan, in program order.
    virtual void execute(ScanContext& ctx) noexcept = 0;
    /// The manual's mnemonic.
    virtual std::string_view mnemonic() const noexcept = 0;
    /// Adds what the instruction drives and owns to the program's declarations.
    virtual void declare(Declarations& /*out*/) const {}
    /// Adds what the devices the instruction uses beyond its operands mean (the words of its
    /// working blocks, a timer's value) as `image` holds them, for the tag export; the operands
    /// themselves are described as they bind (instructions::BindContext::operands).
    virtual void describe(const image::Image& /*image*/, Tags& /*out*/) const {}
    /// Adds the control loops it runs, as `image` holds them now (plcemu/engine/loops.hpp).
    virtual void loops(const image::Image& /*image*/, Loops& /*out*/) const {}
};

/// Something that runs around the program each scan: the plant and the temperature modules.
class Subsystem {
public:
    virtual ~Subsystem() = default;
    /// Before the program: plant → inputs, readings.
    virtual void inputs(ScanContext& /*ctx*/) noexcept {}
    /// After the program: outputs → plant.
    virtual void outputs(ScanContext& /*ctx*/) noexcept {}
};

/// The ordered instruction list.
using Program = std::vector<std::unique_ptr<Instruction>>;

/// The declarations of a built program.
Declarations declarations_of(const Program& program);

/// Fixed parameters of an engine.
struct EngineOptions {
    Duration scan_period = std::chrono::milliseconds(10);  ///< scan_ms
    std::uint8_t station = 1;                              ///< initial station number
};

/// Runs scans over an image.
class Engine {
public:
    /// `image` must outlive the engine; `specials` are the family's special devices (null:
    /// none).
    Engine(image::Image& image,
           EngineOptions options,
           Program program,
           std::unique_ptr<Specials> specials = nullptr);

    /// Adds a subsystem; subsystems run in the order added (inputs) and reverse (outputs).
    void add_subsystem(std::unique_ptr<Subsystem> s);
    /// The special modules FROM/TO reach (owned elsewhere, e.g. by a subsystem; null: none).
    void set_module_bus(ModuleBus* bus) noexcept { modules_ = bus; }
    /// The link master instructions send their requests through (owned elsewhere, e.g. by the
    /// daemon's event loop; null: none).
    void set_outbound(OutboundLink* link) noexcept { outbound_ = link; }

    /// Power-up: the family's special devices take their power-up values. Call once, after
    /// the image holds its retained values.
    void power_up();
    /// Takes over a running PLC's image after a reload: the family's STOP→RUN, no power-up.
    void reload();

    /// Runs one scan starting at simulated time `now` (monotonic, one period after the last).
    /// Returns the station a master asked for during the scan through the family's station
    /// register (R4055 on a FATEK), or nothing. The scan does not take it: whoever knows which
    /// unit IDs are free (the daemon) decides after the scan, and grants it with set_station().
    std::optional<std::uint8_t> step(Duration now, const Calendar& calendar) noexcept;

    /// Runs `n` scans back to back at the scan period (tests, virtual time), granting every
    /// station a master asks for: nothing else answers a unit ID there.
    void run_scans(std::uint64_t n, const Calendar& calendar = {}) noexcept;

    /// RUN (true) or STOP. In STOP a scan still refreshes inputs, runs the plant and keeps the
    /// special devices, but runs no instruction and holds the discrete outputs (Y) off.
    bool running() const noexcept { return running_; }
    /// Enters RUN or STOP (a master's RUN/STOP command). STOP turns the outputs off at once;
    /// RUN is the family's STOP→RUN, as a reload is, and its first scan is a first scan.
    void set_running(bool run) noexcept;
    /// The discretes a master disabled.
    Holds& holds() noexcept { return holds_; }
    /// The same, read-only.
    const Holds& holds() const noexcept { return holds_; }

    /// The station number, which a master may change through a special register.
    const std::uint8_t& station() const { return station_; }
    /// Makes `station` the station in force, shown at once in the family's station register (a
    /// read right after the scan that asked for it sees it).
    void set_station(std::uint8_t station) noexcept;
    /// Scans completed.
    std::uint64_t scans() const { return scans_; }
    /// Simulated time of the last scan start.
    Duration now() const { return last_; }
    /// The scan period.
    Duration scan_period() const { return options_.scan_period; }
    /// The image.
    image::Image& image() { return image_; }
    const image::Image& image() const { return image_; }
    /// Hands the program over (a reload's probe PLC validated it; the live PLC runs it). The
    /// engine is left without instructions.
    Program take_program() noexcept { return std::move(program_); }
    /// The subsystems, in order.
    const std::vector<std::unique_ptr<Subsystem>>& subsystems() const { return subsystems_; }

    /// The program (read-only).
    const Program& program() const { return program_; }

    /// Stages of prefetch().
    static constexpr int kPrefetchStages = 2;
    /// Asks the cache for what step() reads first, without waiting for it: stage 0 the arrays of
    /// parts, stage 1 (at least a memory latency later) the parts themselves. A process scanning
    /// thousands of PLCs finds each PLC's objects cold; warming the next PLC's while this one
    /// scans hides most of that latency (docs/performance.md, "Many PLCs").
    void prefetch(int stage) const noexcept;

private:
    void outputs_off() noexcept;

    image::Image& image_;
    EngineOptions options_;
    Program program_;
    std::unique_ptr<Specials> specials_;
    std::vector<std::unique_ptr<Subsystem>> subsystems_;
    ModuleBus* modules_ = nullptr;
    OutboundLink* outbound_ = nullptr;
    Holds holds_;
    std::uint8_t station_ = 1;
    bool running_ = true;
    bool first_after_run_ = false;
    std::uint64_t scans_ = 0;
    Duration last_{0};
    bool started_ = false;
};

}  // namespace plcemu::engine
