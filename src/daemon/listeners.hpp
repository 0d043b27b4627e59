#pragma once
// The process's listeners, keyed by what they listen on: one TCP or UDP listener per bind
// address and port, one serial line per device, each carrying the protocol its config section
// names (config::listeners_of) and holding the unit table of the PLCs that share it
// (docs/configuration.md, "Sharing a listener"). The Runtime owns it; the PLCs are seated in
// `plcs:` order.

#include <asio.hpp>
#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "plcemu/config/config.hpp"
#include "plcemu/config/listeners.hpp"
#include "plcemu/listener/census.hpp"
#include "plcemu/listener/protocol.hpp"

namespace plcemu::daemon {

/// One PLC as the listeners see it.
struct ListenerMember {
    const config::Config* config;  ///< its config (listener settings, label)
    listener::Seat seat;           ///< what the protocols reach of it
};

/// Every listener of the process.
class Listeners {
public:
    /// `census` (which must outlive it) is handed to every unit table, for the views that show
    /// it.
    Listeners(asio::io_context& io, const listener::Census& census);
    ~Listeners();
    Listeners(const Listeners&) = delete;
    Listeners& operator=(const Listeners&) = delete;

    /// Raises the soft descriptor limit for what the PLCs of `configs` open at a start (their
    /// state files and listeners) and for the clients of their listeners, before any of it is
    /// opened: the state files of a few hundred PLCs alone exceed the usual 1,024.
    static void reserve_descriptors(const std::vector<config::Config>& configs);
    /// Opens every listener the PLCs name; throws when one cannot be had.
    void open(const std::vector<ListenerMember>& plcs);

    /// What the configs `next` ask of the listeners: which PLCs share which one. A function of
    /// the configs alone: a reload makes it on its own thread (at 5,000 PLCs it takes
    /// milliseconds the loop need not spend), and refusal(), unit_clash() and stage() read it.
    struct Plan;
    static std::shared_ptr<const Plan> plan(const std::vector<config::Config>& next);

    /// Why the configs `next` (`plan` theirs) cannot be applied without a restart (they change
    /// which PLCs share a listener), or empty.
    std::string refusal(const std::vector<config::Config>& next, const Plan& plan) const;
    /// A reload's first half: opens the TCP listeners `next` (`plan` theirs) asks for and the
    /// running ones do not provide, before anything changes. False (and logged) when one cannot
    /// be had; then nothing changed.
    bool stage(const std::vector<config::Config>& next, std::shared_ptr<const Plan> plan);
    /// Undoes stage().
    void unstage();
    /// A reload's second half, after the PLCs took their new configs: the staged listeners
    /// replace the old ones, kept ones take the new limits, UDP listeners and serial lines are
    /// reopened with their new settings, and every unit table learns the PLCs' new seats.
    /// `as_staged` is false when a PLC could not be built on its new config and runs on its old
    /// one (in `plcs`): the UDP listeners and serial lines, and what the next reload compares
    /// with, are then those of the configs the PLCs run.
    void apply(const std::vector<ListenerMember>& plcs, bool as_staged = true);

    /// What answers `unit` on a listener of the PLC at `index`, other than that PLC's station:
    /// "plcs[1] (b)'s station on tcp 127.0.0.1:1502", "its simulator unit"; empty when nothing
    /// does (docs/configuration.md, "Sharing a listener").
    std::string holder(std::size_t index, std::uint8_t unit) const;

    /// Why the configs `next` (`plan` theirs), whose PLCs would take the `stations` given (the
    /// stations in force after the reload), cannot be applied: two PLCs on one of the listeners
    /// `next` asks for would answer one unit ID. Empty when none would.
    std::string unit_clash(const std::vector<config::Config>& next,
                           const std::vector<std::uint8_t>& stations,
                           const Plan& plan) const;

    /// The connections of every stream listener open now.
    std::vector<listener::ConnectionFigures> connections() const;

    /// Calls `f` after a serial line's device went away or came back, once the console's
    /// descriptions say so (the status line for the service manager is the caller's).
    void on_change(std::function<void()> f) { on_change_ = std::move(f); }

    /// Closes every listener.
    void stop();
    /// For each PLC, by index, ", tcp ADDR:PORT, rtu DEVICE, fatek tcp ADDR:PORT ...": its open
    /// listeners, for the status line and the console, in one pass over the listeners; only the
    /// first `plcs` PLCs when fewer are asked for.
    std::vector<std::string> describe_all(std::size_t plcs = SIZE_MAX) const;

    struct Listener;

private:
    // Opens the UDP listeners and serial lines of the plan in force; at a reload, `running` are
    // those open before it: each that serves its listener as it is goes on, the rest close.
    void open_reopened(const std::vector<ListenerMember>& plcs,
                       std::vector<std::unique_ptr<Listener>> running,
                       bool at_start);
    void route(const std::vector<ListenerMember>& plcs);
    void describe_seats();
    void raise_fd_limit(std::size_t plcs);

    asio::io_context& io_;
    const listener::Census& census_;
    listener::ClientRoom room_;  // what the descriptor limit leaves the clients of every listener
    std::vector<std::unique_ptr<Listener>> tcp_;       // TCP listeners (kept across reloads)
    std::vector<std::unique_ptr<Listener>> reopened_;  // UDP and serial: kept at a reload
                                                       // unless their settings changed
    std::vector<ListenerMember> plcs_;         // every PLC, by index, as last opened or applied
    std::shared_ptr<const Plan> in_force_;     // plcs_'s plan: what the listeners are
    std::shared_ptr<const Plan> staged_plan_;  // stage()'s, for apply()
    // What stage() prepared for apply(): per new TCP listener, the running one it keeps (index
    // into tcp_) or a new one.
    struct Staged;
    std::vector<Staged> staged_;
    std::vector<std::size_t> stopped_for_stage_;  // running listeners closed to free their port
    std::function<void()> on_change_;
};

}  // namespace plcemu::daemon
