#pragma once
// Shared by the request harnesses: the PLC under test, the reply buffer a transport would own,
// image snapshots and the invariants every reply must keep.

#include <spdlog/spdlog.h>

#include <cstdio>
#include <cstdlib>
#include <algorithm>
#include <array>
#include <cstring>
#include <memory>
#include <span>
#include <vector>

#include "plcemu/config/config.hpp"
#include "support/fake_time.hpp"
#include "plcemu/daemon/plc.hpp"
#include "plcemu/engine/time_control.hpp"
#include "plcemu/modbus/address_map.hpp"
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

/// The request being served and its reply, printed when an invariant breaks.
struct Exchange {
    std::vector<std::uint8_t> request;  ///< as handed to the dispatcher
    std::vector<std::uint8_t> reply;    ///< as read back
};

/// The current exchange.
inline Exchange& exchange() {
    static Exchange e;
    return e;
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

/// The PLC with its simulator-control unit, wired as the daemon wires them.
struct Rig {
    std::unique_ptr<daemon::Plc> plc;               ///< the PLC
    std::unique_ptr<FakeTime> time;                 ///< time control for the simulator unit
    std::unique_ptr<simulator::SimulatorUnit> sim;  ///< the simulator-control unit
    std::uint8_t sim_unit = 0;                      ///< its unit ID

    /// True when a request for `unit` goes to the simulator unit.
    bool is_sim(std::uint8_t unit) { return unit == sim_unit && unit != plc->engine().station(); }
};

/// A fresh rig per input, so that every input replays on its own.
inline Rig make_rig() {
    Rig r;
    r.plc = std::make_unique<daemon::Plc>(harness_config());
    r.time = std::make_unique<FakeTime>(r.plc->engine());
    r.time->max_step = kMaxStep;  // keep one input's work bounded
    r.sim = std::make_unique<simulator::SimulatorUnit>(r.plc->plant(), *r.time);
    r.sim_unit = static_cast<std::uint8_t>(harness_config().simulator.unit);
    r.plc->dispatcher().set_simulator(r.sim.get(), r.sim_unit);
    return r;
}

/// The reply buffer the dispatcher writes into, as a transport owns one.
class Peer {
public:
    /// The buffer handed to the dispatcher.
    modbus::ReplyBuffer buffer() { return out_; }

    /// The first `n` bytes of the buffer: the reply just built.
    std::vector<std::uint8_t> take(std::size_t n) const {
        return {out_.begin(), out_.begin() + static_cast<std::ptrdiff_t>(n)};
    }

private:
    std::array<std::uint8_t, modbus::kMaxReplyAdu> out_{};
};

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
        bytes_.assign(s.begin(), s.end());
    }

    /// True when nothing in the image changed.
    bool same(image::Image& img) const {
        const auto s = img.storage();
        return s.size() == bytes_.size() && std::memcmp(s.data(), bytes_.data(), s.size()) == 0;
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

/// The ranges no Modbus write may change: SPEC §2's read-only items (X, IR, the special relays
/// and registers; written out here rather than taken from the map under test), the map's own
/// list, and the config's write_protect.
inline const std::vector<image::Range>& protected_ranges() {
    static const std::vector<image::Range> r = [] {
        using image::Area;
        std::vector<image::Range> v{
            {Area::X, 0, 256}, {Area::R, 3840, 64}, {Area::M, 1920, 8}, {Area::R, 4136, 3}};
        const auto& map = test::fbs().map().read_only();
        v.insert(v.end(), map.begin(), map.end());
        const auto& wp = harness_config().modbus.write_protect;
        v.insert(v.end(), wp.begin(), wp.end());
        return v;
    }();
    return r;
}

/// Checks the image after a request with function code `fc` that got `answered` (a normal,
/// non-exception reply; broadcasts count as answered). A write to the simulator unit may run
/// scans (its step register), which change the image as scans do: only reads are checked.
inline void check_image(
    image::Image& img, const Snapshot& before, std::uint8_t fc, bool answered, bool to_simulator) {
    if (to_simulator && answered && !reads_only(fc)) return;
    if (!answered || reads_only(fc)) {
        check(before.same(img), "a read, a refused or an unanswered request changed the image");
        return;
    }
    for (const auto& r : protected_ranges()) {
        check(before.same(img, r), "a Modbus write changed a read-only or write-protected device");
    }
}

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
