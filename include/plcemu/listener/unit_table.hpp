#pragma once
// The one owner of unit IDs on a listener: which PLC's station or simulator unit answers an ID,
// and what happens to an ID nobody has (docs/configuration.md, "Sharing a listener"). Every
// protocol on the listener asks it; none reads unit IDs against stations of its own.

#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include "plcemu/engine/engine.hpp"
#include "plcemu/engine/loop_history.hpp"
#include "plcemu/engine/time_control.hpp"
#include "plcemu/image/area.hpp"
#include "plcemu/image/naming.hpp"
#include "plcemu/listener/census.hpp"
#include "plcemu/listener/comm_faults.hpp"
#include "plcemu/listener/traffic.hpp"
#include "plcemu/plant/plant.hpp"
#include "plcemu/modbus/dispatcher.hpp"
#include "plcemu/modbus/unit.hpp"

namespace plcemu::listener {

/// One PLC as the protocols on a listener reach it.
struct Seat {
    std::string label;                         ///< "plcs[1] (kiln)", "" for a plain config's PLC
    const std::uint8_t* station = nullptr;     ///< live: R4055 may change it
    modbus::Dispatcher* dispatcher = nullptr;  ///< the PLC's function codes and identity
    modbus::Unit* unit = nullptr;              ///< the PLC's map over its image, access checks
    std::uint8_t simulator_unit = 0;           ///< the simulator-control unit's ID, 0: none
    modbus::Unit* simulator = nullptr;         ///< the simulator-control unit
    /// The PLC's scan: its image, RUN/STOP and disabled discretes (protocols other than
    /// Modbus reach the devices through it).
    engine::Engine* engine = nullptr;
    /// Devices no master may write whatever the protocol: the profile's read-only devices,
    /// program data and the config's `write_protect`.
    const std::vector<image::Range>* protected_ranges = nullptr;

    // What views other than the wire protocols (the HTTP console and API) show and change.

    std::string id{};          ///< how the API names it: its `name:`, or its position "0", "1"
    std::size_t position = 0;  ///< its place in `plcs:` (0 for a file holding one PLC)
    std::string profile{};     ///< "fbs"
    std::string model{};       ///< "FBs-24MC"
    int scan_ms = 0;           ///< scan period, simulated ms
    std::string listeners{};   ///< "tcp 0.0.0.0:502, fatek tcp 0.0.0.0:500"
    const image::Naming* naming = nullptr;   ///< the family's device names
    engine::TimeControl* time = nullptr;     ///< its scan's time control
    plant::Plant* plant = nullptr;           ///< its simulated process
    Traffic* traffic = nullptr;              ///< what its clients asked of it (null: not kept)
    engine::LoopHistory* history = nullptr;  ///< its loops' recent past (null: not kept)
    CommFaults* faults = nullptr;            ///< its communication faults (null: none)
};

/// What a listener does with a unit ID no PLC on it has: answer it with the protocol's refusal
/// (Modbus TCP: exception 0Bh) or stay silent.
enum class UnknownUnit : std::uint8_t { Refuse, Silent };

/// What a unit ID names.
struct Hit {
    const Seat* seat = nullptr;  ///< the PLC; null: nobody on this listener
    bool simulator = false;      ///< its simulator-control unit rather than its station
    std::uint8_t answer_as = 0;  ///< the ID it answers as: the station, or the simulator unit
};

/// Counters of what no PLC took, for logs and tests.
struct UnitTableStats {
    std::uint64_t unrouted = 0;    ///< requests for a unit no PLC has
    std::uint64_t broadcasts = 0;  ///< broadcasts handed to every PLC
};

/// The unit IDs of one listener. Unit IDs are unique on a listener: the config loader refuses
/// duplicates, and the daemon refuses a station change (R4055) or a reload that would make one.
/// Should two PLCs answer one unit anyway, the first added answers.
class UnitTable {
public:
    /// The PLCs of the listener, in `plcs:` order; their stations are read live.
    void assign(std::vector<Seat> seats) { seats_ = std::move(seats); }
    /// The PLCs.
    const std::vector<Seat>& seats() const { return seats_; }
    /// Sets the policy for unit IDs nobody has.
    void set_unknown_unit(UnknownUnit u) { unknown_ = u; }
    /// The policy for unit IDs nobody has.
    UnknownUnit unknown_unit() const { return unknown_; }
    /// Makes the listener read-only (its config's `read_only`), or not: a protocol that has such
    /// a setting asks it for every request, so a reload changes it at once.
    void set_read_only(bool read_only) { read_only_ = read_only; }
    /// True when nothing may be changed through the listener.
    bool read_only() const { return read_only_; }
    /// Sets the bearer token every write through the listener must carry (HTTP's `token`);
    /// empty: none. Like read_only, asked for every request.
    void set_token(std::string token) { token_ = std::move(token); }
    /// The bearer token writes need; empty: none.
    const std::string& token() const { return token_; }
    /// Host names the listener answers to besides its addresses and `localhost` (HTTP's
    /// `hosts`: a page from any other name may be a DNS-rebinding attack).
    void set_hosts(std::vector<std::string> hosts) { hosts_ = std::move(hosts); }
    /// Those names.
    const std::vector<std::string>& hosts() const { return hosts_; }

    /// The PLC that has `unit` as its station or simulator unit. `device_itself` says whether the
    /// ID also names "the device itself" (Modbus TCP's 0 and 255, implementation guide
    /// §4.4.1.2): that is the PLC when the listener has only one, and nobody when it is shared.
    /// A miss is counted.
    Hit find(std::uint8_t unit, bool device_itself = false) noexcept;
    /// The client whose request is being answered (the listener sets it around each frame;
    /// null between them): a protocol records the exchange in the PLC's Traffic for it.
    void set_serving(const Client* client) noexcept { serving_ = client; }
    /// The client being served, or null.
    const Client* serving() const noexcept { return serving_; }
    /// A client left: no PLC of the listener lists it any more.
    void client_gone(std::uint64_t client) noexcept {
        for (const Seat& s : seats_) {
            if (s.traffic != nullptr) s.traffic->gone(client);
            if (s.faults != nullptr) s.faults->client_gone(client);
        }
    }
    /// What becomes of the answer being made (a protocol says it as it judges the request,
    /// and may add to it as it frames the answer; the listener takes it with the answer).
    Fate& fate() noexcept { return fate_; }
    /// Takes the answer's fate, leaving none for the next.
    Fate take_fate() noexcept { return std::exchange(fate_, Fate{}); }
    /// True when the listener is to refuse new connections: every PLC on it has the fault
    /// `refuse_connections` (a shared listener keeps accepting for the others).
    bool refusing() const noexcept {
        for (const Seat& s : seats_) {
            if (s.faults == nullptr || !s.faults->refuses_connections()) return false;
        }
        return !seats_.empty();
    }
    /// The process's figures beside its PLCs' (null: not kept), for views that show them.
    void set_census(const Census* census) noexcept { census_ = census; }
    /// Those figures, or null.
    const Census* census() const noexcept { return census_; }
    /// Counts a broadcast handed to every PLC.
    void count_broadcast() noexcept { ++stats_.broadcasts; }

    /// Counters since start.
    const UnitTableStats& stats() const { return stats_; }

private:
    std::vector<Seat> seats_;
    UnknownUnit unknown_ = UnknownUnit::Refuse;
    bool read_only_ = false;
    std::string token_;
    std::vector<std::string> hosts_;
    const Client* serving_ = nullptr;
    Fate fate_{};
    const Census* census_ = nullptr;
    UnitTableStats stats_;
};

}  // namespace plcemu::listener
