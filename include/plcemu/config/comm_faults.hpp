#pragma once
// Communication faults (docs/communication-faults.md): what a PLC's answers suffer on the wire,
// switched from the config's `faults:`, the simulator-control unit, the REST API, the console
// and the pytest kit, all with the same names. A plain value: the listeners apply it
// (plcemu/listener/comm_faults.hpp).

#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "plcemu/image/area.hpp"
#include "plcemu/image/naming.hpp"

namespace plcemu::config {

/// How a serial reply is spoilt: a wrong checksum, cut short, or a pause inside it longer than
/// the line's t1.5.
enum class Garble : std::uint8_t { None, Crc, Short, Gap };

/// The faults in force for one PLC, and the requests they apply to.
struct CommFaultSettings {
    // Faults.
    std::uint32_t delay_min_ms = 0;   ///< `delay_ms`: every matching reply held this long ...
    std::uint32_t delay_max_ms = 0;   ///< ... or uniformly up to this (= min: fixed)
    std::uint32_t drop_every = 0;     ///< every Nth matching request is not answered (0: off)
    double drop_probability = 0;      ///< each matching request is not answered with this chance
    std::uint32_t seed = 1;           ///< the generator of delays and drops
    std::uint8_t exception = 0;       ///< answered with this exception, nothing served (0: off)
    bool offline = false;             ///< nothing is answered at all
    bool refuse_connections = false;  ///< new TCP connections are refused
    std::optional<std::uint32_t> disconnect_after;  ///< TCP closed after N requests (0: at once)
    bool reset = false;                             ///< closed with RST rather than FIN
    Garble garble = Garble::None;                   ///< serial replies spoilt
    bool stop = false;                              ///< the PLC leaves RUN

    // Scope: which requests the faults above apply to.
    std::uint8_t unit = 0;                ///< only this unit ID (0: any)
    std::uint8_t function = 0;            ///< only this function code or FATEK command (0: any)
    std::optional<image::Range> devices;  ///< only requests that reach these devices (`from`,
                                          ///< `count`)

    bool operator==(const CommFaultSettings&) const = default;
    /// True when at least one fault is switched on.
    bool any() const;
};

/// The limits every view checks against (docs/communication-faults.md, "Fields").
inline constexpr std::uint32_t kMaxCommDelayMs = 60000;
inline constexpr std::uint32_t kMaxCommCount = 65535;  ///< drop_every, disconnect_after, count

/// Why `s` cannot be switched on ("delay_ms: the first bound is above the second"), or "".
std::string comm_fault_refusal(const CommFaultSettings& s);

/// The range `count` devices from `from` ("R100", "WM800": 16 bits a word) cover, or nothing
/// when `from` is no device of `naming` or `count` is 0 or above kMaxCommCount.
std::optional<image::Range> comm_fault_range(const image::Naming& naming,
                                             std::string_view from,
                                             std::uint32_t count);

/// The name of a garble kind: "crc", "short", "gap" ("none" for None).
std::string_view garble_name(Garble g);
/// The kind a name says, or nothing.
std::optional<Garble> garble_named(std::string_view name);

/// One line per fault that is on ("delay 300 ms", "exception 04", "drop every 3rd"), in the
/// order of the fields; empty when none is.
std::vector<std::string> comm_fault_lines(const CommFaultSettings& s);
/// The scope in words: "unit 2, function 03, R100-R109", or "every request".
std::string comm_fault_scope(const CommFaultSettings& s, const image::Naming& naming);

}  // namespace plcemu::config
