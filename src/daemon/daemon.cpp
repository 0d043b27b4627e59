#include "daemon.hpp"

#include <spdlog/spdlog.h>

#include <asio.hpp>

#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <ctime>
#include <memory>
#include <stdexcept>

#include "daemon/listeners.hpp"
#include "daemon/master_link.hpp"
#include "daemon/notify.hpp"
#include "daemon/retirer.hpp"
#include "daemon/persistence.hpp"
#include "daemon/release_memory.hpp"
#include "daemon/reload.hpp"
#include "daemon/reload_thread.hpp"
#include "daemon/scan_driver.hpp"
#include "daemon/scan_timer.hpp"
#include "daemon/station_guard.hpp"
#include "daemon/step_rounds.hpp"
#include "plcemu/daemon/plc.hpp"
#include "plcemu/image/state_file.hpp"
#include "plcemu/profiles/profile.hpp"
#include "simulator/simulator_unit.hpp"

namespace plcemu::daemon {

namespace {

// Where relative state files go when systemd gives the service a state directory
// (StateDirectory=); "" otherwise.
std::string state_directory() {
    const char* dir = std::getenv("STATE_DIRECTORY");
    return dir != nullptr ? dir : "";
}

// One PLC of the process: its state file, its Plc, its master port and its scan driver, on the
// event loop the Runtime owns (which also owns the listeners, shared or not). A reload builds the
// new Plc beside the running one and swaps it in only when it validated.
class Host {
public:
    Host(asio::io_context& io,
         ScanTimer& timer,
         StepRounds& rounds,
         SyncThread& syncs,
         const Listeners& listeners,
         std::size_t index,
         config::Config loaded)
        : io_(io),
          timer_(timer),
          rounds_(rounds),
          syncs_(syncs),
          file_station_(loaded.station),
          cfg_(std::make_shared<const config::Config>(std::move(loaded))),
          prefix_(cfg_->label.empty() ? "" : cfg_->label + ": "),
          guard_(listeners, index, cfg_->label),
          faults_(prefix_, &profiles::of(*cfg_).naming(), plc_layout(*cfg_)) {}
    // A start that failed half-way: the sync thread must not outlive the state file it syncs.
    ~Host() {
        if (sync_id_ != 0) syncs_.remove(sync_id_);
    }
    Host(const Host&) = delete;
    Host& operator=(const Host&) = delete;

    const config::Config& config() const { return *cfg_; }
    // What the listeners' protocols reach of the PLC: its station (live), its Modbus side and
    // its simulator unit.
    listener::Seat seat() const {
        listener::Seat s;
        s.label = cfg_->label;
        s.station = &plc_->engine().station();
        s.dispatcher = &plc_->dispatcher();
        s.unit = &plc_->unit();
        s.simulator_unit = static_cast<std::uint8_t>(cfg_->simulator.unit);
        s.simulator = cfg_->simulator.unit != 0 ? sim_.get() : nullptr;
        s.engine = &plc_->engine();
        s.protected_ranges = &plc_->unit().protected_ranges();
        s.position = cfg_->index < 0 ? 0 : static_cast<std::size_t>(cfg_->index);
        s.id = cfg_->name.empty() ? std::to_string(s.position) : cfg_->name;
        s.profile = cfg_->profile;
        s.model = cfg_->model;
        s.scan_ms = cfg_->scan_ms;
        s.naming = &profiles::of(*cfg_).naming();
        s.time = driver_.get();
        s.plant = &plc_->plant();
        s.traffic = &traffic_;
        s.history = &history_;
        s.faults = &faults_;
        return s;
    }

    // Opens the state file, builds the Plc and its master port and starts scanning; throws when
    // one cannot. The Runtime opens the listeners.
    // `opened`: its state file, as open_state_files() opened it.
    void open(OpenedState opened) {
        Start start = Start::Fresh;
        if (cfg_->persistence.enabled) {
            if (opened.error) {
                // Named as the PLC's other lines are: which of 5,000 files is in use elsewhere.
                try {
                    std::rethrow_exception(opened.error);
                } catch (const std::exception& e) {
                    if (prefix_.empty()) throw;
                    throw std::runtime_error(prefix_ + e.what());
                }
            }
            state_ = std::move(opened.file);
            for (const auto& n : state_->notes()) {
                if (n.warning) {
                    spdlog::warn("{}{}", prefix_, n.text);
                } else {
                    spdlog::info("{}{}", prefix_, n.text);
                }
            }
            sync_id_ =
                syncs_.add(*state_, std::chrono::milliseconds(cfg_->persistence.sync_ms), prefix_);
            if (state_->retained()) start = Start::Retained;
        } else {
            spdlog::info("{}persistence disabled: nothing is retained across restarts", prefix_);
            heap_.assign(image::Image::storage_size(plc_layout(*cfg_)), std::byte{0});
        }
        plc_ = std::make_unique<Plc>(
            cfg_, storage(), start, std::nullopt,
            state_ ? std::optional(state_->retentive_before()) : std::nullopt);
        // The fault `stop` is RUN/STOP of whichever program runs (a reload keeps it).
        faults_.on_stop([this](bool stop) { plc_->engine().set_running(!stop); });
        faults_.set(cfg_->faults);
        open_master(true);
        start_scanning(false);

        spdlog::info("{}plcemud {}: profile {}, model {}, station {}, scan {} ms, time scale {}",
                     prefix_, version(), cfg_->profile, cfg_->model, int(cfg_->station),
                     cfg_->scan_ms, cfg_->time_scale);
        if (cfg_->listing.empty()) {
            spdlog::info("{}program: {} instruction(s)", prefix_, cfg_->program.size());
        } else {
            // A listing's lines as written (--print-program numbers its steps).
            spdlog::info("{}program: instruction list of {} lines", prefix_, cfg_->listing.size());
        }
    }

    void stop() {
        if (driver_) driver_->stop();
        master_.reset();
    }

    // The first scan, at `first`, once every PLC and listener of the process is open.
    void start(ScanDriver::Clock::time_point first) { driver_->start_at(first); }
    // One scan period in real time.
    ScanDriver::Clock::duration scan_period() const {
        return std::chrono::duration_cast<ScanDriver::Clock::duration>(
            std::chrono::duration<double, std::milli>(cfg_->scan_ms / cfg_->time_scale));
    }

    // After the loop ended: what ran, and the state file closed. False when the disk did not
    // take the state file's last writes.
    bool close() {
        spdlog::info("{}stopped after {} scans", prefix_, plc_->engine().scans());
        if (driver_) {
            // Scan-start lateness against the real-time deadlines (scripts/bench.sh reads it).
            const auto& l = driver_->lateness();
            spdlog::info("{}scan lateness: {} scans, p50 {} us, p99 {} us, max {} us, {} over 1 ms",
                         prefix_, l.scans, l.percentile(0.50).count(), l.percentile(0.99).count(),
                         std::chrono::duration_cast<std::chrono::microseconds>(l.max).count(),
                         l.over_1ms);
        }
        master_.reset();
        sim_.reset();
        driver_.reset();
        plc_.reset();
        if (sync_id_ != 0) syncs_.remove(sync_id_);
        sync_id_ = 0;
        if (!state_) return true;
        const bool in_place = state_->in_place();
        if (const int error = state_->close(); error != 0) {
            spdlog::error(
                "{}state file {}: the last sync failed ({}); left marked open: the next start "
                "recovers what the disk holds",
                prefix_, state_->path(), std::strerror(error));
            return false;
        }
        if (!in_place) {
            spdlog::warn(
                "{}state file {} closed, but not at its path (deleted or moved away while in "
                "use): the next start begins without its retentive values",
                prefix_, state_->path());
            return true;
        }
        spdlog::info("{}state file {} closed", prefix_, state_->path());
        return true;
    }

    // `listeners`: ", tcp ADDR:PORT, rtu DEVICE" as Listeners::describe_all() says.
    std::string status_line(const std::string& listeners) const {
        std::string s = prefix_ + "station " + std::to_string(plc_->engine().station()) + listeners;
        if (state_) s += ", state " + state_->path();
        return s;
    }

    // The station the PLC would have under `next`: the config's new station when it changed;
    // otherwise the one in force, which a master may have set through R4055.
    std::uint8_t station_under(const config::Config& next) const {
        return next.station == file_station_ ? plc_->engine().station() : next.station;
    }

    // Whether `next` keeps the image where it is: persistence on or off as now, and the file in
    // use, as placed (a one-PLC file made a plcs: entry gets another default name).
    bool same_state_file(const config::Config& next) const {
        if (next.persistence.enabled != (state_ != nullptr)) return false;
        if (!state_) return true;
        // As the start would find it: `dir/./x.state` and `x.state` beside a relative config
        // are the file it holds.
        return config::state_file_key(config::state_file_path(next, state_directory())) ==
               config::state_file_key(state_->path());
    }

    // Why `next` cannot be applied without a restart, or empty.
    std::string refusal(const config::Config& next) const {
        if (plc_layout(next).size != plc_->image().layout().size || next.profile != cfg_->profile) {
            return prefix_ + "the profile's image layout changed; restart plcemud to apply it";
        }
        return {};
    }

    // A reload's second half: applies a validated config on the loop (the Runtime staged the
    // listeners). Returns the previous Plc, for the Runtime to retire once no listener routes to
    // its dispatcher; null when the new one could not be built and the previous one runs on.
    std::unique_ptr<Plc> apply(config::Config next, engine::Program program) {
        // Asked once: each answer walks the path's links on the loop.
        const bool same_file = same_state_file(next);
        if (!same_file) {
            spdlog::warn(
                "reload: {}the state file becomes {} at the next start (persistence.enabled "
                "or persistence.file, or a one-PLC config made a plcs: list or back); the image "
                "stays in {}",
                prefix_,
                next.persistence.enabled ? config::state_file_path(next, state_directory())
                                         : std::string("none"),
                state_ ? state_->path() : std::string("memory"));
        }
        // A station a master set through R4055 stays, unless the config's station changed (from
        // what the file said the last time, not from the station in force).
        const std::uint8_t file_station = next.station;
        const std::uint8_t live = plc_->engine().station();
        const std::uint8_t station = station_under(next);
        next.station = cfg_->station;  // the station's change is said below, from the live one
        auto changes = config_changes(*cfg_, next, state_directory());
        next.station = station;
        if (station != live) {
            changes.insert(changes.begin(), "station: " + std::to_string(live) + " -> " +
                                                std::to_string(next.station));
        }
        // The state file stays the one in use until a restart, and later reloads compare with it.
        if (!same_file) {
            // What runs is then not what the file says: no later reload finds it unchanged, and
            // each says again where the image stays.
            next.fingerprint = {};
        }
        next.persistence.enabled = cfg_->persistence.enabled;
        next.persistence.file = cfg_->persistence.file;
        // Moved, not copied: a program of 100,000 instructions costs a second to copy.
        auto applied = std::make_shared<const config::Config>(std::move(next));
        driver_->stop();
        std::unique_ptr<Plc> plc;
        try {
            plc = std::make_unique<Plc>(applied, storage(), Start::Reload, std::move(program));
        } catch (const std::exception& e) {
            spdlog::error("reload: {}{}; still running its previous configuration", prefix_,
                          e.what());
            driver_->start();
            return nullptr;
        }
        plc->plant().restore(plc_->plant().state());
        // RUN/STOP and the disabled discretes are a master's doing, not the config's: the new
        // program takes them over (docs/profile-fbs.md, "FATEK protocol").
        plc->engine().holds() = plc_->engine().holds();
        plc->engine().set_running(plc_->engine().running());
        std::unique_ptr<Plc> old = std::move(plc_);
        plc_ = std::move(plc);
        // Faults switched at run time stay, unless the config's `faults:` changed.
        if (!(applied->faults == cfg_->faults)) faults_.set(applied->faults);
        cfg_ = std::move(applied);
        file_station_ = file_station;
        // The new program's MBUS starts afresh on a new port; the old one's request is dropped.
        master_.reset();
        try {
            open_master(false);
        } catch (const std::exception& e) {
            spdlog::error("reload: {}mbus: {}; running without the master port", prefix_, e.what());
        }
        start_scanning();
        if (state_) state_->set_retentive(plc_layout(*cfg_).retentive);
        if (sync_id_ != 0) {
            syncs_.set_period(sync_id_, std::chrono::milliseconds(cfg_->persistence.sync_ms));
        }

        if (changes.empty())
            spdlog::info("reload: {}no setting changed; program restarted", prefix_);
        for (const auto& c : changes) spdlog::info("reload: {}{}", prefix_, c);
        spdlog::info("reload: {}done; station {}, image kept", prefix_,
                     int(plc_->engine().station()));
        return old;
    }

    // A reload that found this `plcs:` entry as it was: nothing of the PLC is touched (its
    // program, plant, presets and master port run on). At debug: the Runtime says how many.
    void keep() const {
        spdlog::debug("reload: {}no setting changed; running on untouched", prefix_);
    }

private:
    std::span<std::byte> storage() { return state_ ? state_->storage() : std::span(heap_); }

    // The master port the program polls other devices through (VB MBUS), on the same loop:
    // its completions wait for the next scan, which never waits for them. A serial device that
    // is missing stops a start; at a reload it is tried again at every transfer.
    void open_master(bool at_start) {
        const auto master = profiles::of(*cfg_).master(*cfg_);
        if (!master) return;
        master_ = open_master_link(io_, *master, at_start);
        plc_->engine().set_outbound(master_.get());
        spdlog::info("{}mbus: master via {}", prefix_, master_->description());
    }

    // `now`: false at start, where the Runtime starts every PLC's scans at once when all are
    // open, so that opening the later ones does not make the first ones' first scans late.
    void start_scanning(bool now = true) {
        // A frozen simulation stays frozen across a reload, with the steps it was asked for.
        const bool frozen = driver_ && driver_->frozen();
        const std::uint64_t steps = driver_ ? driver_->pending_steps() : 0;
        driver_ = std::make_unique<ScanDriver>(timer_, rounds_, plc_->engine(), cfg_->time_scale,
                                               prefix_);
        if (frozen) driver_->set_frozen(true);
        // The simulator-control unit, on the same listeners as the PLC; a read-only gateway
        // keeps it read-only too unless simulator.writable says otherwise.
        sim_ = std::make_unique<simulator::SimulatorUnit>(
            plc_->plant(), *driver_, cfg_->simulator.writable.value_or(!cfg_->modbus.read_only),
            &faults_, &profiles::of(*cfg_).naming());
        driver_->record_loops(history_);
        // R4055: a station another unit on the PLC's listeners answers is refused.
        driver_->on_station_request([this](std::uint8_t s) { return !guard_.taken(s); });
        if (now) driver_->start();
        if (steps > 0) driver_->step(steps);
    }

    asio::io_context& io_;
    ScanTimer& timer_;
    StepRounds& rounds_;
    SyncThread& syncs_;
    std::uint8_t file_station_;  // the station the config file gave at the last start or reload
    std::shared_ptr<const config::Config> cfg_;  // shared with the running Plc
    std::string prefix_;                         // "plcs[1] (kiln): " in log lines
    ListenerStationGuard guard_;                 // the stations R4055 may not take
    std::unique_ptr<image::StateFile> state_;
    SyncThread::Id sync_id_ = 0;   // 0 = persistence disabled
    std::vector<std::byte> heap_;  // the image when persistence is disabled
    std::unique_ptr<Plc> plc_;
    // What its clients asked, kept across reloads; the protocols write it through the seat.
    mutable listener::Traffic traffic_;
    // Its loops' trends, kept once the console looked at them, and across reloads.
    mutable engine::LoopHistory history_;
    // Its communication faults, kept across reloads; the protocols judge requests by them.
    mutable listener::CommFaults faults_;
    std::unique_ptr<MasterLink> master_;
    std::unique_ptr<ScanDriver> driver_;
    std::unique_ptr<simulator::SimulatorUnit> sim_;
};

// The running daemon: one event loop for every PLC of the config (a `plcs:` list or the one PLC
// of a plain config), their listeners (shared where the config says so), and what a signal does
// to them. One scan timer wakes every PLC's scan driver; each keeps its own deadlines, since PLCs
// scan at periods and time scales of their own and the simulator unit freezes one PLC.
class Runtime {
public:
    Runtime(std::string config_path, config::Overrides overrides)
        : config_path_(std::move(config_path)),
          overrides_(overrides) {}
    // An exception out of run() after a reload must not meet a joinable thread.
    ~Runtime() { join_threads(); }
    Runtime(const Runtime&) = delete;
    Runtime& operator=(const Runtime&) = delete;

    int run() {
        std::vector<config::Config> loaded = config::load_plcs(config_path_, overrides_);
        log_level_ = loaded.front().log.level;
        spdlog::set_level(spdlog::level::from_str(log_level_));
        // Everything the config can get wrong, found before any file or port is touched.
        probe_all(loaded);
        Listeners::reserve_descriptors(loaded);
        for (auto& c : loaded) {
            hosts_.push_back(std::make_unique<Host>(io_, scan_timer_, step_rounds_, syncs_,
                                                    listeners_, hosts_.size(), std::move(c)));
        }
        std::vector<const config::Config*> configs;
        for (const auto& h : hosts_) configs.push_back(&h->config());
        // Each PLC is built as soon as its state file is had, while the next files are made.
        open_state_files(configs, state_directory(), std::time(nullptr),
                         [this](std::size_t i, OpenedState s) { hosts_[i]->open(std::move(s)); });
        // A serial line's device gone or back: the status line says so too.
        listeners_.on_change([this] {
            if (notify_.listening()) notify_.status(status_line());
        });
        listeners_.open(members());
        // PLCs start their scans spread over the scan period in slots of 1 ms, as PLCs powered
        // up one by one drift apart: 500 PLCs of 10 ms scans then wake the loop ten times a
        // period, 50 scans each, instead of once with 500 (where the last would wait for the 499
        // scans before it) or 500 times (a timer wake-up costs more than a scan).
        // The PLCs of one slot share one deadline to the nanosecond, so one wake-up runs them.
        const auto now = ScanDriver::Clock::now();
        for (std::size_t i = 0; i < hosts_.size(); ++i) {
            const auto period = hosts_[i]->scan_period();
            const auto slots = std::max<std::int64_t>(1, period / std::chrono::milliseconds(1));
            hosts_[i]->start(now + period * (static_cast<std::int64_t>(i) % slots) / slots);
        }

        arm_signals();
        arm_watchdog_timer();
        notify_.ready(status_line());
        io_.run();
        // A reload still preparing (a big config takes seconds to build) is not waited for.
        const bool abandoned = reload_thread_.abandon();
        if (abandoned) spdlog::info("reload: abandoned, the daemon stops");
        join_threads();
        // A state file the disk did not take whole makes the stop a failure (exit status 1).
        bool closed = true;
        for (auto& h : hosts_) closed = h->close() && closed;
        hosts_.clear();
        const int status = closed ? 0 : 1;
        if (abandoned) {
            // The state files are closed; the reload's thread still runs and may be using what
            // exit() would destroy (the profiles' tables), so the process ends here, at once.
            spdlog::default_logger()->flush();
            std::fflush(nullptr);
            std::_Exit(status);
        }
        return status;
    }

private:
    // Every PLC's config and seat, in `plcs:` order, for the listeners.
    std::vector<ListenerMember> members() const {
        std::vector<ListenerMember> v;
        v.reserve(hosts_.size());
        for (const auto& h : hosts_) v.push_back({&h->config(), h->seat()});
        return v;
    }

    // The watchdog hears from the event loop that runs the scans: a scan that hangs stops the
    // pings. A timer of its own, not the scans, because a PLC may scan seldom (a 1 s scan at
    // time scale 0.01 is one scan in 100 s) or not at all (frozen) while the loop is well.
    // Every quarter of the interval: a timer late by half the interval still pings in time.
    void arm_watchdog_timer() {
        if (!notify_.watchdog_enabled()) return;
        watchdog_timer_.expires_after(notify_.watchdog_interval() / 4);
        watchdog_timer_.async_wait([this](const asio::error_code& ec) {
            if (ec) return;
            notify_.watchdog();
            arm_watchdog_timer();
        });
    }

    void arm_signals() {
        signals_.async_wait([this](const asio::error_code& ec, int sig) {
            if (ec) return;
            if (sig == SIGHUP) {
                begin_reload();
                arm_signals();
                return;
            }
            spdlog::info("signal {}: stopping", sig == SIGINT ? "SIGINT" : "SIGTERM");
            notify_.stopping();
            watchdog_timer_.cancel();
            listeners_.stop();
            for (auto& h : hosts_) h->stop();
            scan_timer_.stop();
            io_.stop();
        });
    }

    // What `systemctl status` shows: each PLC's station and endpoints, as many PLCs as one
    // message carries, then how many more there are. Made only when a manager listens.
    std::string status_line() const {
        if (!notify_.listening()) return {};
        // A PLC's part and its separator take more than 8 bytes ("; station 1"): no more PLCs
        // than this can show, and only theirs are described.
        constexpr std::size_t kMost = Notifier::kStatusRoom / 8;
        constexpr std::size_t kTail = 32;  // "; and 4999 more PLCs"
        const std::vector<std::string> described = listeners_.describe_all(kMost);
        std::string s;
        for (std::size_t i = 0; i < hosts_.size(); ++i) {
            const std::string part =
                hosts_[i]->status_line(i < described.size() ? described[i] : std::string());
            const bool last = i + 1 == hosts_.size();
            if (i > 0 && s.size() + 2 + part.size() + (last ? 0 : kTail) > Notifier::kStatusRoom) {
                const std::size_t more = hosts_.size() - i;
                s += "; and " + std::to_string(more) + (more == 1 ? " more PLC" : " more PLCs");
                break;
            }
            s += (i == 0 ? "" : "; ") + part;
        }
        return s;
    }

    // What a reload thread prepared: the new configs, validated, with their programs built; or
    // why they were rejected.
    struct Prepared {
        std::vector<config::Config> configs;
        std::vector<engine::Program> programs;        // empty for an unchanged PLC's
        std::vector<bool> unchanged;                  // the PLCs whose config is as it runs
        std::vector<std::string> errors;              // a config's errors, one per line
        std::shared_ptr<const Listeners::Plan> plan;  // the listeners the configs ask for
    };

    // What a reload leaves behind, freed off the loop (and before the memory is given back):
    // the PLCs it replaced, the configs it read for PLCs that did not change (thousands of them
    // take tens of milliseconds to free) and the listeners' plan its thread made.
    struct Leftovers {
        std::vector<std::unique_ptr<Plc>> plcs;
        std::vector<config::Config> configs;
        std::shared_ptr<const Listeners::Plan> plan;
    };

    // SIGHUP: the new config is read, validated and its programs built on a thread of its own (a
    // program of 100,000 instructions takes seconds), then swapped in on the loop. A SIGHUP
    // during a reload runs one more reload after it.
    void begin_reload() {
        if (reloading_) {
            reload_again_ = true;
            return;
        }
        reloading_ = true;
        notify_.reloading();
        spdlog::info("SIGHUP: reloading {}", config_path_);
        auto p = std::make_shared<Prepared>();
        // With `plcs:`, a reload is a download to the PLCs whose entry changed; the PLC of a
        // single-PLC file is restarted at every reload (the STOP->RUN the profiles' docs
        // describe), changed or not.
        std::vector<config::Fingerprint> running;
        if (hosts_.front()->config().index >= 0) {
            running.reserve(hosts_.size());
            for (const auto& h : hosts_) running.push_back(h->config().fingerprint);
        }
        // The work owns copies of what it reads: a shutdown may leave it running after the
        // Runtime is gone.
        auto work = [p, path = config_path_, overrides = overrides_, running = std::move(running)] {
            try {
                p->configs = config::load_plcs(path, overrides);
                // A PLC whose config reads as it did is neither built nor touched: 5,000 PLCs
                // with one setpoint changed rebuild one (docs/operations.md, "Reload").
                p->unchanged.assign(p->configs.size(), false);
                for (std::size_t i = 0; i < p->configs.size() && i < running.size(); ++i) {
                    p->unchanged[i] = p->configs[i].fingerprint == running[i];
                }
                // Built on images of their own (the live ones are not touched), and never
                // scanned: their programs, bound and checked, are the ones the live PLCs will run.
                p->programs = probe_all(p->configs, p->unchanged);
                p->plan = Listeners::plan(p->configs);
                // The YAML's trees and the probed PLCs are gone; the process's memory falls
                // back before the swap adds the new PLCs.
                release_freed_memory();
            } catch (const config::ConfigError& e) {
                p->errors = e.lines();
            } catch (const std::exception& e) {
                p->errors = {e.what()};
            }
        };
        reload_thread_.start(
            work, [this, p] { asio::post(io_, [this, p] { finish_reload(std::move(*p)); }); });
    }

    void join_threads() noexcept {
        reload_thread_.join();
        retirer_.stop();
    }

    void finish_reload(Prepared p) {
        reloading_ = false;
        if (p.errors.empty()) {
            if (auto why = reload(p); !why.empty()) p.errors.push_back(std::move(why));
        }
        if (!p.errors.empty()) {
            for (const auto& e : p.errors) spdlog::error("reload: {}", e);
            spdlog::error("reload: configuration rejected; still running the previous one");
            ++census_.reloads_rejected;
        } else {
            ++census_.reloads_applied;
        }
        notify_.ready(status_line());
        if (reload_again_) {
            reload_again_ = false;
            begin_reload();
        }
    }

    // Applies validated configs on the loop, all or none: what needs a restart, or a listener
    // that cannot be had, keeps every PLC on its previous config. Returns why it refused, or
    // empty.
    std::string reload(Prepared& p) {
        if (p.configs.size() != hosts_.size()) {
            return "the config has " + std::to_string(p.configs.size()) + " PLC(s), " +
                   std::to_string(hosts_.size()) +
                   " are running; restart plcemud to add or remove PLCs";
        }
        for (std::size_t i = 0; i < hosts_.size(); ++i) {
            if (p.configs[i].name != hosts_[i]->config().name) {
                // A one-PLC config has no label: it is the config's only PLC.
                const std::string& was = hosts_[i]->config().label;
                return p.configs[i].label + ": was " +
                       (was.empty() ? "the config's one PLC" : was) +
                       "; restart plcemud to rename or reorder PLCs";
            }
            // A PLC whose config reads as it runs has nothing to refuse.
            if (p.unchanged[i]) continue;
            if (auto why = hosts_[i]->refusal(p.configs[i]); !why.empty()) return why;
        }
        if (auto why = listeners_.refusal(p.configs, *p.plan); !why.empty()) return why;
        // Unit IDs are compared as they will be: with the stations masters set through R4055
        // that the reload keeps.
        std::vector<std::uint8_t> stations;
        for (std::size_t i = 0; i < hosts_.size(); ++i) {
            stations.push_back(hosts_[i]->station_under(p.configs[i]));
        }
        if (auto why = listeners_.unit_clash(p.configs, stations, *p.plan); !why.empty()) {
            return why;
        }
        if (!listeners_.stage(p.configs, p.plan)) return "a listener could not be opened";
        auto left = std::make_unique<Leftovers>();
        // One process, one log: `log:` is no PLC's setting, and never makes one change.
        const std::string level = p.configs.front().log.level;
        std::size_t kept = 0;
        bool all_built = true;  // else a PLC runs on its previous config
        for (std::size_t i = 0; i < hosts_.size(); ++i) {
            if (p.unchanged[i]) {
                hosts_[i]->keep();
                ++kept;
                continue;
            }
            auto old = hosts_[i]->apply(std::move(p.configs[i]), std::move(p.programs[i]));
            if (old) {
                left->plcs.push_back(std::move(old));
            } else {
                all_built = false;
            }
        }
        listeners_.apply(members(), all_built);
        if (level != log_level_) {
            spdlog::info("reload: log.level: {} -> {}", log_level_, level);
            spdlog::set_level(spdlog::level::from_str(level));
            log_level_ = level;
        }
        if (hosts_.front()->config().index >= 0) {
            spdlog::info("reload: applied to {} of {} PLCs; {} unchanged run on untouched",
                         hosts_.size() - kept, hosts_.size(), kept);
        }
        // Freed off the loop (a program may be large); nothing on the loop refers to them any
        // more: routers, scan drivers and simulator units were replaced.
        left->configs = std::move(p.configs);
        left->plan = std::move(p.plan);
        retirer_.retire(std::move(left));
        return {};
    }

    std::string config_path_;
    config::Overrides overrides_;
    std::string log_level_;  // `log.level` in force
    asio::io_context io_{1};
    Notifier notify_;
    Retirer<Leftovers> retirer_;
    ScanTimer scan_timer_{io_};
    // Every PLC's queued steps, a slice per turn of the loop.
    StepRounds step_rounds_{io_};
    // What /metrics shows of the process beside its PLCs (connections are asked of listeners_).
    listener::Census census_{.connections = [this] { return listeners_.connections(); }};
    SyncThread syncs_{census_};  // every PLC's state file, on one thread
    std::vector<std::unique_ptr<Host>> hosts_;
    Listeners listeners_{io_, census_};
    asio::signal_set signals_{io_, SIGINT, SIGTERM, SIGHUP};
    ReloadThread reload_thread_;
    bool reloading_ = false;
    bool reload_again_ = false;
    asio::steady_timer watchdog_timer_{io_};
};

}  // namespace

engine::Program probe(const config::Config& c) {
    try {
        std::vector<std::string> warnings;
        Plc plc(c, {}, Start::Retained, build_program(c, nullptr, &warnings));
        // Said at each start, reload and --check-config, as the vendors' tools say them.
        for (const auto& w : warnings) {
            spdlog::warn("{}program: {}", c.label.empty() ? "" : c.label + ": ", w);
        }
        return plc.engine().take_program();
    } catch (const config::ConfigError& e) {
        if (c.label.empty()) throw;
        throw e.prefixed(c.label + ": ");
    }
}

std::vector<engine::Program> probe_all(const std::vector<config::Config>& configs,
                                       const std::vector<bool>& skip) {
    config::Errors errors;
    std::vector<engine::Program> programs;
    programs.reserve(configs.size());
    for (std::size_t i = 0; i < configs.size(); ++i) {
        if (i < skip.size() && skip[i]) {
            programs.emplace_back();
            continue;
        }
        errors.attempt([&] { programs.push_back(probe(configs[i])); });
    }
    errors.raise();
    return programs;
}

int run_daemon(const std::string& config_path, const config::Overrides& overrides) {
    return Runtime(config_path, overrides).run();
}

}  // namespace plcemu::daemon
