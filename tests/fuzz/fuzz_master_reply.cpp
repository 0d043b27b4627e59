// libFuzzer harness: replies a Modbus master (FNC149 MBUS) gets back, judged against the request
// it sent.
//
// Input: six header bytes, then the reply. Header: function selector (1, 2, 3, 4, 5, 6, 15, 16),
// start address (2 bytes), quantity (1–64, as MBUS sends), station (1–247), mode. Mode bit 0
// clear: the rest is one reply PDU, as the TCP master hands it on. Set: the rest is records
// [n][pause][n bytes], raw chunks of a 9600 8N1 line arriving `pause` half-characters after the
// previous chunk went over the wire; the RTU framer (t1.5, t3.5, CRC) ends frames and rtu_reply
// judges each as the station's reply, as in the RTU master.
//
// Invariants: a frame taken as a reply is whole, its CRC good and its address the station's; a
// reply accepted as Ok carries the request's function code, a read's byte count for the
// quantity and a write's echo; bit values are 0 or 1; an exception reply is the function code
// with bit 7 and one code byte, and its code is reported.

#include <algorithm>
#include <array>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <optional>
#include <span>

#include "modbus/crc.hpp"
#include "modbus/master_pdu.hpp"
#include "modbus/rtu_framer.hpp"
#include "modbus/rtu_reply.hpp"
#include "serial_chunks.hpp"

using namespace plcemu;

namespace {

constexpr std::array<std::uint8_t, 8> kFunctions{1, 2, 3, 4, 5, 6, 15, 16};
constexpr std::size_t kHeader = 6;

void check(bool ok, const char* what) {
    if (ok) return;
    std::fprintf(stderr, "invariant broken: %s\n", what);
    std::abort();
}

struct Request {
    std::array<std::uint8_t, modbus::kMaxRequestPdu> pdu{};
    std::size_t size = 0;
    std::uint16_t quantity = 0;
};

void judge(const Request& req, std::span<const std::uint8_t> reply) {
    std::array<std::uint16_t, 64> values{};
    values.fill(0xEEEE);
    const auto c = modbus::check_reply({req.pdu.data(), req.size}, reply, values);
    const std::uint8_t fc = req.pdu[0];
    switch (c.verdict) {
        case modbus::ReplyVerdict::Ok: {
            check(!reply.empty() && reply[0] == fc, "accepted a reply to another function");
            if (!modbus::is_write(fc)) {
                const bool bits = fc == 1 || fc == 2;
                const std::size_t bytes = bits ? (req.quantity + 7u) / 8u : req.quantity * 2u;
                check(reply.size() == 2 + bytes && reply[1] == bytes,
                      "accepted a read reply with a wrong byte count");
                for (std::size_t i = 0; i < req.quantity; ++i) {
                    check(!bits || values[i] <= 1, "a bit read gave a value other than 0 or 1");
                }
                for (std::size_t i = req.quantity; i < values.size(); ++i) {
                    check(values[i] == 0xEEEE, "a read wrote past its quantity");
                }
            } else {
                const std::size_t echoed = 5;
                check(reply.size() == echoed &&
                          std::memcmp(reply.data(), req.pdu.data(), echoed) == 0,
                      "accepted a write reply that does not echo the request");
            }
            break;
        }
        case modbus::ReplyVerdict::Exception:
            check(reply.size() == 2 && reply[0] == (fc | 0x80) && reply[1] == c.exception,
                  "an exception verdict for something else than an exception reply");
            break;
        case modbus::ReplyVerdict::Malformed:
            break;
    }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    if (size < kHeader) return 0;
    Request req;
    const std::uint8_t fc = kFunctions[data[0] % kFunctions.size()];
    const auto address = static_cast<std::uint16_t>(data[1] << 8 | data[2]);
    req.quantity = static_cast<std::uint16_t>(fc == 5 || fc == 6 ? 1 : 1 + data[3] % 64);
    const auto station = static_cast<std::uint8_t>(1 + data[4] % 247);
    const bool framed = (data[5] & 1) != 0;
    std::array<std::uint16_t, 64> out{};
    for (std::size_t i = 0; i < out.size(); ++i) out[i] = static_cast<std::uint16_t>(i * 0x0101);
    req.size =
        modbus::encode_request(fc, address, req.quantity, {out.data(), req.quantity}, req.pdu);
    check(req.size > 0, "no request for a function and quantity MBUS sends");
    std::span<const std::uint8_t> in(data + kHeader, size - kHeader);

    if (!framed) {
        judge(req, in);
        return 0;
    }
    auto handle = [&](const std::optional<modbus::RtuFrame>& f) {
        if (!f) return;
        const modbus::RtuReply r = modbus::rtu_reply(*f, station);
        if (r.outcome != modbus::MasterOutcome::Reply) return;
        const auto b = f->bytes;
        check(f->verdict == modbus::RtuVerdict::Ok && b.size() >= 4 && b[0] == station,
              "a frame that is not the station's whole frame taken as its reply");
        const std::uint16_t crc = modbus::crc16(b.data(), b.size() - 2);
        check(b[b.size() - 2] == (crc & 0xFF) && b[b.size() - 1] == crc >> 8,
              "a reply with a bad CRC taken");
        check(r.pdu.data() == b.data() + 1 && r.pdu.size() == b.size() - 3,
              "the reply PDU is not the frame between address and CRC");
        judge(req, r.pdu);
    };
    fuzz::feed_chunks(in, modbus::RtuTiming::for_line(9600, 'N', 8, 1), handle);
    return 0;
}
