// libFuzzer harness: Modbus RTU frames into the dispatcher.
//
// Input: one control byte, then records. Control bits 0-2: run one engine scan after every n-th
// frame (0 = never; fuzz::kMaxScans at most). Bit 7 clear: records are [n][n bytes], each an
// address + PDU that gets a correct CRC appended and goes to the dispatcher, as the RTU transport
// delivers a frame once its CRC checked. Bit 7 set: records are [n][pause][n bytes], raw chunks of
// a 9600 8E1 line arriving `pause` half-characters after the previous chunk went over the wire; the
// RTU framer (t1.5, t3.5, CRC) decides what reaches the dispatcher, as in the daemon.
//
// Invariants: the framer hands on only whole frames with a good CRC; a reply is absent or one
// frame with a correct CRC, the request's address (never a broadcast's) and its function code;
// the station always gets one; a read, a refusal or silence to a unicast changes nothing in the
// image; no write changes X, read-only items or write-protected ranges.

#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

#include "fuzz_support.hpp"
#include "modbus/crc.hpp"
#include "modbus/rtu_framer.hpp"
#include "serial_chunks.hpp"

using namespace plcemu;

namespace {

void check_reply(fuzz::Rig& rig,
                 std::span<const std::uint8_t> req,
                 std::span<const std::uint8_t> rep) {
    const std::uint8_t unit = req[0];
    if (rep.empty()) {
        fuzz::check(unit != rig.plc().engine().station() && !rig.is_sim(unit),
                    "no reply to a request for the station or the simulator");
        return;
    }
    fuzz::check(unit != 0, "a broadcast was answered");
    fuzz::check(rep.size() >= 5 && rep.size() <= modbus::RtuFramer::kMaxFrame,
                "reply size out of range");
    const std::uint16_t crc = modbus::crc16(rep.data(), rep.size() - 2);
    fuzz::check(rep[rep.size() - 2] == (crc & 0xFF) && rep[rep.size() - 1] == (crc >> 8),
                "reply CRC is wrong");
    fuzz::check(rep[0] == unit, "reply address differs");
    fuzz::check_reply_pdu(req.subspan(1, req.size() - 3), rep.subspan(1, rep.size() - 3));
}

// Serves frames that passed the CRC check and checks what came of each.
class Server {
public:
    explicit Server(fuzz::Rig& rig)
        : rig_(rig) {}

    void serve(std::span<const std::uint8_t> frame) {
        static fuzz::Peer peer;
        fuzz::exchange() = {frame, {}};
        fuzz::check(frame.size() >= 4 && frame.size() <= modbus::RtuFramer::kMaxFrame,
                    "frame size out of range");
        daemon::Plc& plc = rig_.plc();
        watch_.before(plc.image(), frame[1], frame);
        const auto rep = fuzz::serve(rig_, peer, testing::Framing::Rtu, frame);
        fuzz::exchange().reply = rep;
        fuzz::record(rep);
        check_reply(rig_, frame, rep);
        // A broadcast write is applied without an answer; judge it as answered.
        const bool answered = frame[0] == 0 || (rep.size() > 1 && (rep[1] & 0x80) == 0);
        watch_.after(plc.image(), frame[1], answered, rig_.is_sim(frame[0]));
    }

    /// Runs a scan, fuzz::kMaxScans at most.
    void scan() {
        if (scans_ == fuzz::kMaxScans) return;
        ++scans_;
        watch_.settle(rig_.plc().image());
        rig_.plc().engine().run_scans(1);
        watch_.scanned();
    }

    /// At the end of the input: the last reads are checked.
    void finish() { watch_.settle(rig_.plc().image()); }

private:
    fuzz::Rig& rig_;
    fuzz::ImageWatch watch_;
    unsigned scans_ = 0;
};

// One input on `rig` (just reset).
void run(fuzz::Rig& rig, const std::uint8_t* data, std::size_t size) {
    const std::uint8_t control = data[0];
    const bool raw = (control & 0x80) != 0;
    const unsigned scan_every = control & 0x07;
    std::span<const std::uint8_t> in(data + 1, size - 1);

    Server server(rig);
    unsigned frames = 0;
    auto after_frame = [&] {
        if (scan_every != 0 && ++frames % scan_every == 0) server.scan();
    };

    if (!raw) {
        static std::vector<std::uint8_t> frame;  // kept: its capacity serves every input
        while (in.size() >= 2) {
            const std::size_t n = std::min<std::size_t>(in[0], in.size() - 1);
            frame.assign(in.begin() + 1, in.begin() + 1 + static_cast<std::ptrdiff_t>(n));
            in = in.subspan(1 + n);
            const std::uint16_t crc = modbus::crc16(frame.data(), frame.size());
            frame.push_back(static_cast<std::uint8_t>(crc & 0xFF));
            frame.push_back(static_cast<std::uint8_t>(crc >> 8));
            // The framer drops these (too short, too long).
            if (frame.size() < 4 || frame.size() > modbus::RtuFramer::kMaxFrame) continue;
            server.serve(frame);
            after_frame();
        }
        server.finish();
        return;
    }

    auto handle = [&](const std::optional<modbus::RtuFrame>& f) {
        if (!f || f->verdict != modbus::RtuVerdict::Ok) return;
        const auto b = f->bytes;
        fuzz::check(b.size() >= 4 && b.size() <= modbus::RtuFramer::kMaxFrame,
                    "the framer passed a frame of an impossible size");
        const std::uint16_t crc = modbus::crc16(b.data(), b.size() - 2);
        fuzz::check(b[b.size() - 2] == (crc & 0xFF) && b[b.size() - 1] == crc >> 8,
                    "the framer passed a frame with a bad CRC");
        server.serve(b);
        after_frame();
    };
    fuzz::feed_chunks(in, modbus::RtuTiming::for_line(9600, 'E', 8, 1), handle);
    server.finish();
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    if (size < 1) return 0;
    fuzz::run_input(data, size, run);
    return 0;
}
