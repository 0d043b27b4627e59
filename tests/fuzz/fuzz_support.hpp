#pragma once
// Shared by the request harnesses: the PLC under test (one for every input, reset between
// inputs, and every so often checked against a new one), the reply buffer a transport would own,
// image snapshots and the invariants every reply must keep.

#include <spdlog/spdlog.h>

#include <cstdio>
#include <cstdlib>
#include <algorithm>
#include <array>
#include <cstring>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "plcemu/config/config.hpp"
#include "support/fake_time.hpp"
#include "support/modbus_oracle.hpp"
#include "plcemu/daemon/plc.hpp"
#include "profiles/fbs/special_registers.hpp"
#include "support/profiles.hpp"
#include "plcemu/engine/time_control.hpp"
#include "plcemu/modbus/address_map.hpp"
#include "modbus/mbap.hpp"
#include "modbus_slave/rtu.hpp"
#include "modbus_slave/tcp.hpp"
#include "plcemu/plant/thermal_plant.hpp"
#include "simulator/simulator_unit.hpp"

namespace plcemu::fuzz {

/// The config every request harness runs: config/default.yaml's PLC (temperature table, MOV,
/// TPCTL over the thermal plant) with write protection to check against.
inline constexpr const char* kConfig = R"(profile: fbs
model: FBs-24MC
station: 1
modbus:
  tcp: {bind: 127.0.0.1, port: 0}
  write_protect: [D100-D199, M1000-M1009]
temperature:
  table: R5000
  modules: [TC6:K, RTD6:PT100_DIN]
init:
  R5000: [0xA556, 2, 10000, 20000, 0x0101, 0x0002]
  R100: [1500, 1500, 1500, 1500, 1500, 1500, 1500, 1500, 1500, 1500]
  R110: [50, 50, 50, 50, 50, 50, 50, 50, 50, 50]
program:
  - MOV: {en: M1926, s: WM800, d: R4012}
  - TPCTL: {en: M0, hc: M1, md: 0, sn: 0, zn: 10, yn: Y30, sv: R100, os: R110, pr: R120,
            ir: R130, dr: R140, or: R200, wr: R300, err: M100, alm: M101}
)";

/// Most scans one simulator "step" write runs here (the daemon runs them all; a cap keeps
/// inputs fast).
inline constexpr std::uint64_t kMaxStep = 8;

/// The request being served and its reply, printed when an invariant breaks (views of the
/// input and of the reply buffer, valid while the input runs).
struct Exchange {
    std::span<const std::uint8_t> request;  ///< as handed to the dispatcher
    std::span<const std::uint8_t> reply;    ///< as read back
};

/// The current exchange.
inline Exchange& exchange() {
    static Exchange e;
    return e;
}

// clang's no_builtin keeps the loops below from becoming the calls they replace; GCC, which
// builds the harnesses only to replay their corpora (tests/fuzz/replay_main.cpp), has no such
// attribute, and a call there costs nothing that matters.
#if defined(__clang__)
    #define PLCEMU_FUZZ_NO_BUILTIN(...) , no_builtin(__VA_ARGS__)
#else
    #define PLCEMU_FUZZ_NO_BUILTIN(...)
#endif

/// A word of a byte buffer, read and written in place.
typedef std::uint64_t __attribute__((may_alias, aligned(1))) BufferWord;

/// Copies `n` bytes between two image-sized buffers of the harness (the image's storage and its
/// copies), several times per input. The loop is the copy, unchecked: memcpy's ASan interceptor
/// would check both ranges' shadow first, a cost as large as the copy, and UBSan's checks of each
/// step would keep the loop from being vectorized; neither has anything to find in buffers that
/// are whole by construction.
__attribute__((no_sanitize("address", "undefined")
                   PLCEMU_FUZZ_NO_BUILTIN("memcpy", "memmove"))) inline void
copy_bytes(std::byte* dst, const std::byte* src, std::size_t n) {
    const std::size_t words = n / sizeof(BufferWord);
    auto* d = reinterpret_cast<BufferWord*>(dst);
    const auto* s = reinterpret_cast<const BufferWord*>(src);
    for (std::size_t i = 0; i < words; ++i) d[i] = s[i];
    for (std::size_t i = words * sizeof(BufferWord); i < n; ++i) dst[i] = src[i];
}

/// True when `n` bytes of two such buffers are equal (see copy_bytes).
__attribute__((no_sanitize("address", "undefined")
                   PLCEMU_FUZZ_NO_BUILTIN("memcmp", "bcmp"))) inline bool
same_bytes(const std::byte* a, const std::byte* b, std::size_t n) {
    const std::size_t words = n / sizeof(BufferWord);
    const auto* x = reinterpret_cast<const BufferWord*>(a);
    const auto* y = reinterpret_cast<const BufferWord*>(b);
    std::uint64_t diff = 0;
    for (std::size_t i = 0; i < words; ++i) diff |= x[i] ^ y[i];
    for (std::size_t i = words * sizeof(BufferWord); i < n; ++i) {
        diff |= static_cast<std::uint64_t>(a[i] ^ b[i]);
    }
    return diff == 0;
}

/// Reports a broken invariant the way libFuzzer records a crash.
[[noreturn]] inline void fail(const char* what) {
    std::fprintf(stderr, "invariant broken: %s\n  request:", what);
    for (std::uint8_t b : exchange().request) std::fprintf(stderr, " %02x", b);
    std::fprintf(stderr, "\n  reply:  ");
    for (std::uint8_t b : exchange().reply) std::fprintf(stderr, " %02x", b);
    std::fprintf(stderr, "\n");
    std::abort();
}

/// Aborts unless `ok`.
inline void check(bool ok, const char* what) {
    if (!ok) fail(what);
}

/// The parsed harness config (parsed once: the config harness covers the parser).
inline const config::Config& harness_config() {
    static const config::Config c = [] {
        spdlog::set_level(spdlog::level::off);
        return config::parse_config(kConfig, "fuzz.yaml");
    }();
    return c;
}

using testing::FakeTime;

/// The PLC with its simulator-control unit, wired as the daemon wires them. Building one costs
/// far more than an input (the program binds its operands, the plant and the measurement are set
/// up), so one rig serves every input and reset() puts it back to the state it was built in.
class Rig {
public:
    Rig() { build(); }
    Rig(const Rig&) = delete;
    Rig& operator=(const Rig&) = delete;

    /// The PLC.
    daemon::Plc& plc() { return *plc_; }
    /// Modbus TCP on a listener of the PLC's own, as the daemon serves it.
    modbus_slave::ModbusTcp& tcp() { return *tcp_; }
    /// Modbus RTU on a serial line of the PLC's own, as the daemon serves it.
    modbus_slave::ModbusRtu& rtu() { return *rtu_; }

    /// True when a request for `unit` goes to the simulator unit.
    bool is_sim(std::uint8_t unit) { return unit == sim_unit_ && unit != plc_->engine().station(); }

    /// Back to the state of a new rig: the station as built, a power-up (the next scan is a
    /// first scan, which starts TPCTL and the temperature measurement afresh), the image and the
    /// plant as built, the time control as new. The simulator unit keeps nothing of its own (it
    /// reads the plant and the time control afresh for every request).
    void reset() {
        if (plc_->engine().station() != station_) restore_station();
        // The plant changes in scans (the simulator unit's steps run scans too) and in writes to
        // the simulator unit, nowhere else: without either, it is still as built.
        const bool plant_touched = plant_touched_ || plc_->engine().scans() > 0;
        plc_->engine().power_up();
        const auto s = plc_->image().storage();
        copy_bytes(s.data(), image_.data(), s.size());  // also undoes power_up()'s writes
        if (plant_touched) thermal() = *plant_;
        plant_touched_ = false;
        tcp_->units().set_unknown_unit(policy_);
        reset_time();
    }

    /// Notes that something outside reset()'s view used the plant (a sensor sample).
    void touch_plant() { plant_touched_ = true; }

private:
    // A master set the station (R4055 = 55xxh, docs/profile-fbs.md), which power_up() keeps. A
    // first scan over the image as built with R4055 = 5500h + the station as built sets it back;
    // what else that scan does, reset() undoes as it undoes an input's scans. A rig that still
    // differs is built anew.
    void restore_station() {
        plc_->engine().power_up();
        image::Image& img = plc_->image();
        copy_bytes(img.storage().data(), image_.data(), image_.size());
        img.set_word(image::Area::R, profiles::fbs::special::kStation,
                     static_cast<std::uint16_t>(0x5500 | station_));
        plc_->engine().run_scans(1);
        if (plc_->engine().station() != station_) build();
    }

    void build() {
        // Shared, not copied: the config is the same for every rig.
        static const auto config = std::make_shared<const config::Config>(harness_config());
        tap_.reset();
        sim_.reset();
        time_.reset();
        plant_touched_ = false;
        plc_ = std::make_unique<daemon::Plc>(config);
        const auto s = plc_->image().storage();
        image_.assign(s.begin(), s.end());
        plant_.emplace(thermal());
        station_ = plc_->engine().station();
        sim_unit_ = static_cast<std::uint8_t>(config->simulator.unit);
        policy_ = config->modbus.tcp.unknown_unit == config::UnknownUnit::Silent
                      ? listener::UnknownUnit::Silent
                      : listener::UnknownUnit::Refuse;
        attach_simulator();
    }

    // The plant as a value, to keep and put back whole (a Plant shows only what the rest of the
    // emulator needs): the harness's config runs the thermal plant, the one model.
    plant::ThermalPlant& thermal() { return dynamic_cast<plant::ThermalPlant&>(plc_->plant()); }

    void attach_simulator() {
        tcp_.reset();
        rtu_.reset();
        tap_.reset();
        sim_.reset();
        time_.emplace(plc_->engine());
        reset_time();
        sim_.emplace(plc_->plant(), *time_);
        tap_.emplace(*sim_, plant_touched_);
        const listener::Seat seat{
            "", &plc_->engine().station(), &plc_->dispatcher(), &plc_->unit(), sim_unit_, &*tap_};
        tcp_.emplace(listener::ProtocolSetup{{seat}, policy_, {}});
        rtu_.emplace(listener::ProtocolSetup{{seat}, listener::UnknownUnit::Silent, {}});
    }

    // The simulator unit as the dispatcher sees it, noting every write that lands (a write is
    // what changes the plant's parameters or faults).
    class Tap final : public modbus::Unit {
    public:
        Tap(simulator::SimulatorUnit& unit, bool& written)
            : unit_(unit),
              written_(written) {}
        modbus::Window resolve(modbus::Table table,
                               std::uint16_t addr,
                               std::uint16_t qty,
                               bool write) noexcept override {
            return unit_.resolve(table, addr, qty, write);
        }
        void written(modbus::Table table, std::uint16_t addr, std::uint16_t qty) noexcept override {
            written_ = true;
            unit_.written(table, addr, qty);
        }

    private:
        simulator::SimulatorUnit& unit_;
        bool& written_;
    };

    // Every field of the fake as a new one has it (the recorded calls kept only their capacity).
    void reset_time() {
        FakeTime& t = *time_;
        t.set_frozen(false);
        t.scale = 1.0;
        t.frozen_log.clear();
        t.queued = 0;
        t.cancels = 0;
        t.steps.clear();
        t.frozen_when_stepped.clear();
        t.fixed_time.reset();
        t.max_step = kMaxStep;  // keep one input's work bounded
    }

    std::unique_ptr<daemon::Plc> plc_;
    std::optional<FakeTime> time_;
    std::optional<simulator::SimulatorUnit> sim_;
    std::optional<Tap> tap_;
    std::optional<modbus_slave::ModbusTcp> tcp_;  // over the PLC and tap_
    std::optional<modbus_slave::ModbusRtu> rtu_;
    bool plant_touched_ = false;    // a write reached the simulator unit since the last reset
    std::vector<std::byte> image_;  // the image as built
    std::optional<plant::ThermalPlant> plant_;  // the plant as built
    std::uint8_t station_ = 0;                  // the station as built
    std::uint8_t sim_unit_ = 0;                 // the simulator unit's ID
    listener::UnknownUnit policy_{};            // the unknown-unit policy as built
};

/// What an input made the PLC do, for comparing two runs of it: every reply, then the image,
/// the engine and the plant as the input left them.
class Trace {
public:
    /// Starts recording (a trace records nothing until then).
    void start() {
        on_ = true;
        bytes_.clear();
    }
    /// Records a reply.
    void reply(std::span<const std::uint8_t> rep) {
        if (!on_) return;
        put(rep.size());
        bytes_.insert(bytes_.end(), rep.begin(), rep.end());
    }
    /// Records the state the input left, and stops recording.
    void finish(Rig& rig) {
        if (!on_) return;
        auto& plc = rig.plc();
        const auto s = plc.image().storage();
        const auto* b = reinterpret_cast<const std::uint8_t*>(s.data());
        image_at_ = bytes_.size();
        bytes_.insert(bytes_.end(), b, b + s.size());
        state_at_ = bytes_.size();
        put(plc.engine().scans());
        put(static_cast<std::uint64_t>(plc.engine().now().count()));
        put(plc.engine().station());
        auto& p = plc.plant();
        for (int c = 0; c < plant::kChannels; ++c) {
            putd(p.true_temperature(c));
            putd(p.heater_power(c));
            putd(p.drive_now(c));
            putd(p.params(c).ambient_c);
            putd(p.params(c).k_c);
            putd(p.params(c).tau_s);
            putd(p.params(c).dead_time_s);
            putd(p.params(c).noise_c);
            const Faults f = p.faults(c);
            put(std::uint64_t{f.sensor_broken} | std::uint64_t{f.heater_open} << 1 |
                std::uint64_t{f.heater_shorted} << 2 | std::uint64_t{f.reading_frozen} << 3);
            const engine::SensorSample x = p.sense(c);  // the sensor as the next scan sees it
            put(x.broken);
            putd(x.celsius);
        }
        on_ = false;
    }
    /// The bytes recorded.
    const std::vector<std::uint8_t>& bytes() const { return bytes_; }
    /// Where byte `i` of the record is, in words.
    std::string where(std::size_t i) const {
        char w[96];
        if (i < image_at_) {
            std::snprintf(w, sizeof w, "in the replies (byte %zu)", i);
        } else if (i < state_at_) {
            std::snprintf(w, sizeof w, "in the image (storage byte %zu)", i - image_at_);
        } else {
            std::snprintf(w, sizeof w, "in the engine or the plant (byte %zu)", i - state_at_);
        }
        return w;
    }

private:
    using Faults = plant::Faults;
    void put(std::uint64_t v) {
        for (int i = 0; i < 8; ++i) bytes_.push_back(static_cast<std::uint8_t>(v >> (8 * i)));
    }
    void putd(double d) {
        std::uint64_t v;
        std::memcpy(&v, &d, sizeof v);
        put(v);
    }

    bool on_ = false;
    std::vector<std::uint8_t> bytes_;
    std::size_t image_at_ = 0;  // where the image starts in bytes_
    std::size_t state_at_ = 0;  // where the engine and the plant start
};

/// The trace of the run in progress.
inline Trace*& trace() {
    static Trace* t = nullptr;
    return t;
}

/// Records a reply in the trace of the run in progress.
inline void record(std::span<const std::uint8_t> rep) {
    if (trace() != nullptr) trace()->reply(rep);
}

/// How often an input is run a second time on a new rig to check that reset() left nothing of
/// the inputs before it (PLCEMU_FUZZ_CHECK_RESET=1: every input).
inline constexpr std::uint64_t kCheckEvery = 1024;

/// Runs `body(rig, data, size)` for one input on the shared rig, reset first. Every
/// kCheckEvery-th input also runs on a new rig, and the two runs must do the same: replies,
/// image, engine and plant.
template <class Body>
void run_input(const std::uint8_t* data, std::size_t size, Body body) {
    static Rig rig;
    static std::uint64_t n = 0;
    static const bool every = std::getenv("PLCEMU_FUZZ_CHECK_RESET") != nullptr;
    static std::vector<std::uint8_t> previous;  // the input before, named when a check fails
    const bool check = every || ++n % kCheckEvery == 0;
    rig.reset();
    exchange() = {};
    if (!check) {
        body(rig, data, size);
    } else {
        static Trace reused, fresh;
        reused.start();
        trace() = &reused;
        body(rig, data, size);
        reused.finish(rig);
        rig.touch_plant();  // finish() took sensor samples
        Rig other;
        fresh.start();
        trace() = &fresh;
        body(other, data, size);
        fresh.finish(other);
        trace() = nullptr;
        if (reused.bytes() != fresh.bytes()) {
            const auto& x = reused.bytes();
            const auto& y = fresh.bytes();
            std::size_t i = 0;
            while (i < x.size() && i < y.size() && x[i] == y[i]) ++i;
            std::fprintf(stderr,
                         "reset drift: this input did on the reused rig what it does not do on a "
                         "new one (first difference %s): an input before it left state that "
                         "Rig::reset() missed. Replay the one before, then this one. Input "
                         "before:",
                         reused.where(i).c_str());
            for (std::uint8_t b : previous) std::fprintf(stderr, " %02x", b);
            std::fprintf(stderr, "\n");
            std::abort();
        }
        // This input ran last on `other`: `rig` is reset before the next one anyway.
    }
    previous.assign(data, data + size);
}

/// The reply buffer the dispatcher writes into, as a transport owns one.
class Peer {
public:
    /// The buffer handed to the dispatcher.
    std::span<std::uint8_t> buffer() { return out_; }

    /// The first `n` bytes of the buffer: the reply just built.
    std::span<const std::uint8_t> take(std::size_t n) const {
        check(n <= out_.size(), "reply length beyond the reply buffer");
        return std::span(out_).first(n);
    }

private:
    std::array<std::uint8_t, modbus::kMaxTcpAdu> out_{};
};

/// Serves `adu` on the rig's PLC and on libmodbus beside it (support/modbus_oracle.hpp): where
/// the two are comparable, their replies and writes must be identical. Returns the PLC's reply.
/// What the oracle compared and skipped is printed when the process exits.
inline std::span<const std::uint8_t> serve(Rig& rig,
                                           Peer& peer,
                                           testing::Framing framing,
                                           std::span<const std::uint8_t> adu) {
    static const bool summary_at_exit = [] {
        return std::atexit(
                   [] { std::fputs(testing::ModbusOracle::get().summary().c_str(), stderr); }) == 0;
    }();
    (void)summary_at_exit;
    const auto r = testing::ModbusOracle::get().serve({rig.tcp(), rig.rtu()}, rig.plc().unit(),
                                                      framing, adu, peer.buffer());
    if (!r.mismatch.empty()) fail(r.mismatch.c_str());
    return peer.take(r.size);
}

/// Function codes that only read: a request with one of these never changes the image.
inline bool reads_only(std::uint8_t fc) {
    switch (fc) {
        case 0x05:
        case 0x06:
        case 0x0F:
        case 0x10:
        case 0x16:
        case 0x17:
            return false;
        default:
            return true;
    }
}

/// Exception codes the dispatcher may send.
inline bool known_exception(std::uint8_t code) {
    return code == 0x01 || code == 0x02 || code == 0x03 || code == 0x04 || code == 0x0B;
}

/// A copy of the image storage taken before a request, to compare after it.
class Snapshot {
public:
    /// Copies the image now.
    void take(image::Image& img) {
        const auto s = img.storage();
        bytes_.resize(s.size());
        copy_bytes(bytes_.data(), s.data(), s.size());
    }

    /// True when nothing in the image changed.
    bool same(image::Image& img) const {
        const auto s = img.storage();
        return s.size() == bytes_.size() && same_bytes(s.data(), bytes_.data(), s.size());
    }

    /// True when none of the devices of `r` changed.
    bool same(image::Image& img, const image::Range& r) const {
        const std::size_t elem = image::is_bit_area(r.area) ? 1 : 2;
        const std::size_t off = image::Image::area_offset(img.layout(), r.area) + r.start * elem;
        const std::size_t n = std::size_t{r.count} * elem;
        return std::memcmp(img.storage().data() + off, bytes_.data() + off, n) == 0;
    }

private:
    std::vector<std::byte> bytes_;
};

/// The ranges no Modbus write may change: the map's read-only items (X, IR, the special relays
/// and registers; written out here rather than taken from the map under test), the map's own
/// list, and the config's write_protect.
inline const std::vector<image::Range>& protected_ranges() {
    static const std::vector<image::Range> r = [] {
        using image::Area;
        std::vector<image::Range> v{
            {Area::X, 0, 256}, {Area::R, 3840, 64}, {Area::M, 1920, 8}, {Area::R, 4136, 3}};
        const auto& map = testing::fbs().map().read_only();
        v.insert(v.end(), map.begin(), map.end());
        const auto& wp = harness_config().modbus.write_protect;
        v.insert(v.end(), wp.begin(), wp.end());
        return v;
    }();
    return r;
}

/// The image checks of one input: a read, a refused or an unanswered request changes nothing in
/// the image; a write changes no read-only or write-protected device. A write to the simulator
/// unit may run scans (its step register), which change the image as scans do: only its reads
/// are checked. Reads in a row are checked together, with one compare of the whole image before
/// the next frame that may write, the next scan, or the end of the input: comparing the image
/// after every read was a tenth of a request harness's time (docs/development.md, "Speed").
class ImageWatch {
public:
    /// Before serving `request`, whose function code is `fc`.
    void before(image::Image& img, std::uint8_t fc, std::span<const std::uint8_t> request) {
        if (!reads_only(fc)) settle(img);
        if (!have_) snapshot().take(img);
        have_ = true;
        if (reads_only(fc) && !pending_) {
            // A copy: an RTU frame's buffer is the next frame's.
            first_read_size_ = std::min(request.size(), first_read_.size());
            std::copy_n(request.begin(), first_read_size_, first_read_.begin());
        }
    }

    /// After it was served: `answered` (a normal reply; broadcasts count as answered), for the
    /// simulator unit or not.
    void after(image::Image& img, std::uint8_t fc, bool answered, bool to_simulator) {
        if (reads_only(fc)) {
            pending_ = true;
            return;
        }
        have_ = false;
        if (to_simulator && answered) return;
        if (!answered) {
            check(snapshot().same(img), "a refused or unanswered request changed the image");
            have_ = true;
            return;
        }
        for (const auto& r : protected_ranges()) {
            check(snapshot().same(img, r),
                  "a Modbus write changed a read-only or write-protected device");
        }
    }

    /// Before a scan, and at the end of the input: checks the reads not yet checked.
    void settle(image::Image& img) {
        if (!pending_) return;
        pending_ = false;
        if (snapshot().same(img)) return;
        exchange() = {std::span(first_read_).first(first_read_size_), {}};
        fail(
            "a read changed the image (the request shown, or a read after it before the next "
            "write or scan)");
    }

    /// After a scan: the image is the scan's.
    void scanned() { have_ = false; }

private:
    static Snapshot& snapshot() {
        static Snapshot s;  // kept: its capacity serves every input
        return s;
    }

    bool have_ = false;                           // snapshot() holds the image as it is now
    bool pending_ = false;                        // reads since the snapshot, not yet checked
    std::array<std::uint8_t, 260> first_read_{};  // the first of them
    std::size_t first_read_size_ = 0;
};

/// Most scans one input runs between its frames: what a scan does to the request path (the
/// station a master set through R4055, the specials) shows in the first; more only cost time
/// (docs/development.md, "Speed").
inline constexpr unsigned kMaxScans = 4;

/// Checks a reply PDU (function code onward) against its request PDU: function code echoed or
/// flagged, known exception codes, byte counts that match the request.
inline void check_reply_pdu(std::span<const std::uint8_t> req, std::span<const std::uint8_t> rep) {
    check(!rep.empty() && !req.empty(), "empty PDU");
    const std::uint8_t fc = req[0];
    if (rep[0] == (fc | 0x80)) {
        check(rep.size() == 2, "exception reply of the wrong length");
        check(known_exception(rep[1]), "unknown exception code");
        return;
    }
    check(rep[0] == fc, "reply function code differs from the request's");
    check(rep.size() >= 2, "normal reply without data");
    auto be16 = [](std::span<const std::uint8_t> p, std::size_t i) {
        return static_cast<std::uint16_t>(p[i] << 8 | p[i + 1]);
    };
    switch (fc) {
        case 0x01:
        case 0x02:
            check(req.size() == 5, "read bits served with a malformed request");
            check(rep[1] == (be16(req, 3) + 7) / 8 && rep.size() == 2u + rep[1],
                  "read bits reply byte count");
            break;
        case 0x03:
        case 0x04:
            check(req.size() == 5, "read registers served with a malformed request");
            check(rep[1] == be16(req, 3) * 2 && rep.size() == 2u + rep[1],
                  "read registers reply byte count");
            break;
        case 0x05:
        case 0x06:
        case 0x16:
        case 0x08:
            check(rep.size() == req.size() && std::memcmp(rep.data(), req.data(), req.size()) == 0,
                  "echo reply differs from the request");
            break;
        case 0x0F:
        case 0x10:
            check(rep.size() == 5 && std::memcmp(rep.data(), req.data(), 5) == 0,
                  "write multiple reply is not address and quantity");
            break;
        case 0x17:
            check(req.size() >= 5 && rep[1] == be16(req, 3) * 2 && rep.size() == 2u + rep[1],
                  "read/write registers reply byte count");
            break;
        case 0x11:
            check(rep.size() == 2u + rep[1], "report slave ID byte count");
            break;
        case 0x2B:
            check(rep.size() >= 7 && req.size() == 4 && rep[1] == 0x0E && rep[2] == req[2],
                  "read device identification reply header");
            break;
        default:
            fail("normal reply to a function code the dispatcher does not implement");
    }
}

}  // namespace plcemu::fuzz
