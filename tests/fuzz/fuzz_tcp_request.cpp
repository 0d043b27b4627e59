// libFuzzer harness: a Modbus TCP connection's byte stream into the dispatcher.
//
// Input: one control byte, then the bytes a client sends. Control bits 0-2: run one engine
// scan after every n-th frame (0 = never; fuzz::kMaxScans at most); bit 3: unknown unit IDs stay
// silent instead of getting exception 0Bh. The stream is split into MBAP frames by the server's own
// splitter and ends where the server would stop reading (a bad header closes the connection).
//
// Invariants: each frame gets at most one reply, a well-formed MBAP frame with the request's
// transaction ID and unit ID; a read, a refusal or silence changes nothing in the image; no
// write changes X, read-only items or write-protected ranges. The simulator-control unit is
// served too, as in the daemon.

#include <cstddef>
#include <cstdint>
#include <span>

#include "fuzz_support.hpp"
#include "modbus/mbap.hpp"

using namespace plcemu;

namespace {

void check_reply(fuzz::Rig& rig,
                 bool silent,
                 std::span<const std::uint8_t> req,
                 std::span<const std::uint8_t> rep) {
    const std::uint8_t unit = req[6];
    if (rep.empty()) {
        const std::uint8_t station = rig.plc().engine().station();
        fuzz::check(silent && unit != station && unit != 0xFF && unit != 0 && !rig.is_sim(unit),
                    "no reply to a request for the station, unit 0 or 255 or the simulator");
        return;
    }
    fuzz::check(rep.size() >= 9 && rep.size() <= modbus::kMaxTcpAdu, "reply size out of range");
    const auto f = modbus::next_mbap_frame(rep);
    fuzz::check(f.status == modbus::MbapStatus::Frame && f.size == rep.size(),
                "reply is not exactly one MBAP frame");
    fuzz::check(rep[0] == req[0] && rep[1] == req[1], "reply transaction ID differs");
    fuzz::check(rep[6] == unit, "reply unit ID differs");
    fuzz::check_reply_pdu(req.subspan(7), rep.subspan(7));
}

// One input on `rig` (just reset).
void run(fuzz::Rig& rig, const std::uint8_t* data, std::size_t size) {
    const std::uint8_t control = data[0];
    const unsigned scan_every = control & 0x07;
    const bool silent = (control & 0x08) != 0;
    std::span<const std::uint8_t> stream(data + 1, size - 1);

    static fuzz::Peer peer;
    daemon::Plc& plc = rig.plc();
    rig.tcp().units().set_unknown_unit(silent ? listener::UnknownUnit::Silent
                                              : listener::UnknownUnit::Refuse);
    fuzz::ImageWatch watch;
    unsigned frames = 0;
    unsigned scans = 0;
    for (;;) {
        const modbus::MbapFrame f = modbus::next_mbap_frame(stream);
        if (f.status != modbus::MbapStatus::Frame) break;
        fuzz::check(f.size >= 8 && f.size <= modbus::kMaxTcpAdu && f.size <= stream.size(),
                    "MBAP splitter returned an impossible frame size");
        const auto req = stream.first(f.size);
        stream = stream.subspan(f.size);

        watch.before(plc.image(), req[7], req);
        const auto rep = fuzz::serve(rig, peer, testing::Framing::Tcp, req);
        fuzz::exchange() = {req, rep};
        fuzz::record(rep);
        check_reply(rig, silent, req, rep);
        const bool answered = rep.size() > 7 && (rep[7] & 0x80) == 0;
        watch.after(plc.image(), req[7], answered, rig.is_sim(req[6]));

        if (scan_every != 0 && ++frames % scan_every == 0 && scans < fuzz::kMaxScans) {
            watch.settle(plc.image());
            plc.engine().run_scans(1);
            watch.scanned();
            ++scans;
        }
    }
    watch.settle(plc.image());
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    if (size < 1) return 0;
    fuzz::run_input(data, size, run);
    return 0;
}
