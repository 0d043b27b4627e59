// libFuzzer harness: a FATEK TCP connection's byte stream into the FATEK protocol
// (docs/profile-fbs.md, "FATEK protocol").
//
// Input: the bytes a master sends. The stream is cut by the protocol's own splitter, as the TCP
// listener cuts it, and every piece is answered.
//
// Invariants: the splitter never gives up on the stream (a FATEK connection is never closed for
// its bytes) and cuts only what was received, a frame of at most 508 bytes; a reply is one
// well-formed frame of at most 508 bytes, STX ... ETX with neither inside, a correct checksum, the
// PLC's station, the request's command, and (but for 4E) a known error code; only a request for the
// PLC's station gets one.

#include <algorithm>
#include <array>
#include <cctype>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <memory>
#include <span>
#include <vector>

#include "fatek/checksum.hpp"
#include "fatek/frame.hpp"
#include "fatek/hex.hpp"
#include "fatek/request.hpp"
#include "fatek/stream.hpp"
#include "support/fatek_rig.hpp"

using namespace plcemu;

namespace {

void check(bool ok,
           const char* what,
           std::span<const std::uint8_t> req,
           std::span<const std::uint8_t> rep) {
    if (ok) return;
    std::fprintf(stderr, "invariant broken: %s\n  request:", what);
    for (std::uint8_t b : req) std::fprintf(stderr, " %02x", b);
    std::fprintf(stderr, "\n  reply:  ");
    for (std::uint8_t b : rep) std::fprintf(stderr, " %02x", b);
    std::fprintf(stderr, "\n");
    std::abort();
}

// One FBs PLC on a FATEK listener; reset() puts it back as built.
struct Rig {
    Rig()
        : plc(config::parse_config("profile: fbs\n", "fuzz.yaml")),
          protocol(testing::setup_of(plc)) {
        const auto s = plc.image().storage();
        image.assign(s.begin(), s.end());
    }
    void reset() {
        if (!plc.engine().running()) plc.engine().set_running(true);
        plc.engine().holds().clear();
        const auto s = plc.image().storage();
        std::copy(image.begin(), image.end(), s.begin());
    }
    daemon::Plc plc;
    fatek::FatekStream protocol;
    std::vector<std::byte> image;
};

void check_reply(std::uint8_t station,
                 std::span<const std::uint8_t> req,
                 std::span<const std::uint8_t> rep) {
    const auto r = fatek::parse_request(req);
    if (rep.empty()) {
        check(!r || r->station != station, "no reply to a good frame for the station", req, rep);
        return;
    }
    check(r && r->station == station, "a reply to a frame that is not the station's", req, rep);
    check(rep.size() >= fatek::kFrameOverhead && rep.size() <= fatek::kMaxFrame,
          "reply size out of range", req, rep);
    check(rep.front() == fatek::kStx && rep.back() == fatek::kEtx, "reply not STX ... ETX", req,
          rep);
    const auto inner = rep.subspan(1, rep.size() - 2);
    check(std::none_of(inner.begin(), inner.end(),
                       [](std::uint8_t b) { return b == fatek::kStx || b == fatek::kEtx; }),
          "STX or ETX inside the reply", req, rep);
    const auto sum = fatek::parse_hex(rep.subspan(rep.size() - 3, 2));
    check(sum && *sum == fatek::checksum(rep.first(rep.size() - 3)), "reply checksum", req, rep);
    check(fatek::parse_hex(rep.subspan(1, 2)) == station, "reply station", req, rep);
    const bool loop_back = r->code == 0x4E;
    check(rep[3] == std::toupper(req[3]) && rep[4] == std::toupper(req[4]), "reply command differs",
          req, rep);
    if (loop_back) {
        check(std::equal(rep.begin() + 5, rep.end() - 3, r->data.begin(), r->data.end()),
              "loop-back is not an echo", req, rep);
        return;
    }
    check(rep.size() >= 9, "reply without an error code", req, rep);
    const std::uint8_t e = rep[5];
    check(e == '0' || e == '2' || e == '3' || e == '4' || e == 'A', "unknown error code", req, rep);
    check(e == '0' || rep.size() == 9, "data after an error code", req, rep);
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    static Rig rig;
    rig.reset();
    std::span<const std::uint8_t> stream(data, size);
    std::array<std::uint8_t, fatek::kMaxFrame> out{};
    const std::uint8_t station = rig.plc.engine().station();
    while (!stream.empty()) {
        const listener::Split s = rig.protocol.split(stream);
        check(s.cut != listener::Cut::Bad, "the splitter gave up on the stream", stream, {});
        if (s.cut == listener::Cut::Incomplete) {
            check(stream.size() < fatek::kMaxFrame && stream[0] == fatek::kStx,
                  "waiting for more than a frame", stream, {});
            break;
        }
        // Bytes before an STX are cut off however many they are; a frame is at most 508.
        check(s.size >= 1 && s.size <= stream.size() &&
                  (stream[0] != fatek::kStx || s.size <= fatek::kMaxFrame),
              "splitter returned an impossible size", stream, {});
        const auto req = stream.first(s.size);
        stream = stream.subspan(s.size);
        const std::size_t n = rig.protocol.answer(req, out);
        // What the splitter skips is no frame: the listeners drop it, and it has no answer.
        check(s.cut == listener::Cut::Frame || n == 0, "skipped bytes have an answer", req,
              std::span<const std::uint8_t>(out).first(n));
        check_reply(station, req, std::span<const std::uint8_t>(out).first(n));
    }
    return 0;
}
