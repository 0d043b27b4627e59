#pragma once
// A PLC's communication faults as the protocols meet them (docs/communication-faults.md): one
// object per PLC, kept by its host across reloads, switched by every view (config, simulator
// unit, REST API, console, kit) through set(). A protocol asks judge() about each request after
// its unit table found the PLC, and before the PLC serves it: the verdict says whether to serve
// it, refuse it with an exception or stay silent, and what becomes of the answer on its way out
// (its Fate, which the listener that carries it applies). The simulator-control unit is never
// judged, so a test can always switch the faults off.

#include <chrono>
#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <random>
#include <string>
#include <unordered_map>

#include "plcemu/config/comm_faults.hpp"
#include "plcemu/image/area.hpp"
#include "plcemu/image/layout.hpp"
#include "plcemu/image/naming.hpp"
#include "plcemu/listener/traffic.hpp"

namespace plcemu::listener {

using config::CommFaultSettings;
using config::Garble;

class CommFaults;

/// What becomes of an answer on its way out. The protocol applies what it alone can (a wrong
/// checksum, a cut), the listener the rest (a hold, a pause, a close).
struct Fate {
    enum class Close : std::uint8_t { No, Fin, Reset };
    std::chrono::milliseconds delay{0};  ///< the answer is held this long
    Close close = Close::No;             ///< the TCP connection is closed after the answer
    Garble garble = Garble::None;        ///< a serial answer is spoilt
    /// Set by a protocol for Garble::Gap: the answer's first `gap_at` bytes go out, then a
    /// pause of `gap`, then the rest.
    std::size_t gap_at = 0;
    std::chrono::microseconds gap{0};
    /// The faults of the PLC that answered: a listener that holds too many answers already
    /// (delayed ones, or ones waiting behind them) drops it and tells them
    /// (CommFaults::held_over), so their figures count it dropped.
    CommFaults* by = nullptr;

    /// True when nothing happens to the answer.
    bool none() const {
        return delay.count() == 0 && close == Close::No && garble == Garble::None && gap_at == 0;
    }
};

/// Spoils a serial answer of `size` bytes as its fate says, where the framing does not matter
/// (Garble::Crc is the protocol's, which knows its checksum): Short sends its first half only,
/// Gap pauses for `gap` after its first half. Returns the bytes to send.
inline std::size_t cut_or_pause(Fate& fate, std::size_t size, std::chrono::microseconds gap) {
    if (fate.garble == Garble::Short) return size / 2;
    if (fate.garble == Garble::Gap && size >= 2) {
        fate.gap_at = size / 2;
        fate.gap = gap;
    }
    return size;
}

/// What a protocol does with a request.
struct Verdict {
    enum class Kind : std::uint8_t {
        Serve,      ///< the PLC serves it
        Silent,     ///< nothing is served, nothing answered
        Exception,  ///< nothing is served; the answer is the protocol's refusal `code`
    };
    Kind kind = Kind::Serve;
    std::uint8_t code = 0;  ///< Exception: the code
    bool drop = false;      ///< served, but its answer is lost on the way
    Fate fate{};            ///< what becomes of the answer
};

/// A request as the faults' scope sees it.
struct Asked {
    std::uint8_t unit = 0;                ///< the unit ID or station it named
    std::uint8_t function = 0;            ///< the function code or FATEK command
    std::optional<image::Range> devices;  ///< the devices it reaches, when it names any
    std::optional<image::Range> also;     ///< a second range (Modbus 17h: read and write)
    std::uint64_t client = 0;             ///< Client::id of the connection it came on
    Carrier carrier = Carrier::Stream;    ///< what carried it (disconnects: TCP; garbles: serial)
};

/// One PLC's communication faults.
class CommFaults {
public:
    /// `label` starts its log lines ("plcs[1] (kiln): "); `naming` writes device ranges in them;
    /// `layout`, the PLC's, says which ranges a scope may name.
    explicit CommFaults(std::string label = {},
                        const image::Naming* naming = nullptr,
                        std::optional<image::Layout> layout = std::nullopt);

    /// Why `s` cannot be switched on for this PLC (config::comm_fault_refusal, or a scope
    /// naming devices the PLC does not have), or "". Every view asks it before set().
    std::string refusal(const CommFaultSettings& s) const;

    /// Switches to `s` (refused beforehand by config::comm_fault_refusal when it must be): logs
    /// one line per fault switched on or off, restarts the counters and the generator, and
    /// tells the RUN switch (on_stop) when `stop` changed.
    void set(const CommFaultSettings& s);
    /// Switches every fault off.
    void clear() { set(CommFaultSettings{}); }
    /// The faults in force.
    const CommFaultSettings& settings() const noexcept { return s_; }
    /// True when any fault is on.
    bool active() const noexcept { return active_; }
    /// True when new TCP connections are to be refused.
    bool refuses_connections() const noexcept { return s_.refuse_connections; }
    /// Called with `stop` whenever it changes (the PLC's host stops or restarts its scan).
    void on_stop(std::function<void(bool)> f) { on_stop_ = std::move(f); }
    /// What to do with a request for the PLC.
    Verdict judge(const Asked& a) noexcept;
    /// An answer of this PLC was dropped: its listener held too many already. `delayed`: it
    /// was counted delayed, and is not.
    void held_over(bool delayed) noexcept {
        if (delayed) --figures_.delayed;
        ++figures_.dropped;
    }
    /// A client left: its count of requests towards disconnect_after goes.
    void client_gone(std::uint64_t client) noexcept { served_.erase(client); }

    /// Requests the faults have touched since start, for tests and the console.
    struct Figures {
        std::uint64_t delayed = 0;       ///< answers held
        std::uint64_t dropped = 0;       ///< answers lost
        std::uint64_t refused = 0;       ///< answered with the exception
        std::uint64_t silenced = 0;      ///< not answered while offline
        std::uint64_t disconnected = 0;  ///< connections closed
        std::uint64_t garbled = 0;       ///< serial answers spoilt
    };
    /// Those figures.
    const Figures& figures() const noexcept { return figures_; }

private:
    bool matches(const Asked& a) const noexcept;

    std::string label_;
    const image::Naming* naming_;
    std::optional<image::Layout> layout_;
    CommFaultSettings s_;
    bool active_ = false;
    // Made by set() only for settings that draw from it (drop_probability, a delay range): 5 KB
    // of state that 5,000 PLCs without faults would each carry.
    std::unique_ptr<std::mt19937> random_;
    std::uint64_t matched_ = 0;                                // towards drop_every
    std::unordered_map<std::uint64_t, std::uint32_t> served_;  // per client, disconnect_after
    std::function<void(bool)> on_stop_;
    Figures figures_;
};

}  // namespace plcemu::listener
