#include "serve.hpp"

#include <algorithm>
#include <chrono>
#include <new>

#include "command.hpp"
#include "frame.hpp"
#include "hex.hpp"
#include "reach.hpp"
#include "request.hpp"

namespace plcemu::fatek {

namespace {

// The station no PLC has (docs/profile-fbs.md, "FATEK protocol").
constexpr std::uint8_t kNoStation = 0xFF;

std::size_t execute(const listener::Seat& seat,
                    std::uint8_t station,
                    bool read_only,
                    const Request& req,
                    std::uint8_t* out) noexcept {
    Reply reply(out, station, req.command.data());
    const Command* cmd = req.code ? &commands()[*req.code] : nullptr;
    if (cmd == nullptr || cmd->handler == nullptr) {
        reply.put(static_cast<std::uint8_t>(Error::Format));
        return reply.finish();
    }
    Target plc{*seat.engine, seat.protected_ranges, read_only};
    if (!cmd->error_code) {
        cmd->handler(req.data, plc, reply);
        return reply.finish();
    }
    const std::size_t at = reply.size();
    reply.put(static_cast<std::uint8_t>(Error::None));
    if (const Error e = cmd->handler(req.data, plc, reply); e != Error::None) {
        reply.truncate(at);
        reply.put(static_cast<std::uint8_t>(e));
    }
    return reply.finish();
}

// What the PLC's communication faults make of the request (docs/communication-faults.md).
listener::Verdict judge(listener::UnitTable& units,
                        const listener::Seat& seat,
                        const Request& req) noexcept {
    if (seat.faults == nullptr || !seat.faults->active()) return {};
    listener::Asked a;
    a.unit = req.station;
    a.function = req.code.value_or(0);
    if (const auto& scope = seat.faults->settings().devices; scope && req.code) {
        a.devices = reach_within(*req.code, req.data, seat.engine->image().layout(), *scope);
    }
    if (const listener::Client* c = units.serving()) {
        a.client = c->id;
        a.carrier = c->carrier;
    }
    return seat.faults->judge(a);
}

}  // namespace

std::size_t serve(listener::UnitTable& units,
                  std::span<const std::uint8_t> frame,
                  std::span<std::uint8_t> out) noexcept {
    if (out.size() < kMaxFrame) return 0;
    const bool read_only = units.read_only();
    const auto req = parse_request(frame);
    if (!req || req->station == kNoStation) return 0;
    if (req->station == 0) {
        // Every PLC executes it; none answers (the reply is written and dropped).
        for (const listener::Seat& s : units.seats()) {
            if (s.engine == nullptr) continue;
            if (judge(units, s, *req).kind != listener::Verdict::Kind::Serve) continue;
            execute(s, *s.station, read_only, *req, out.data());
        }
        units.count_broadcast();
        return 0;
    }
    const listener::Hit hit = units.find(req->station);
    if (hit.seat == nullptr || hit.simulator || hit.seat->engine == nullptr) return 0;
    const listener::Verdict v = judge(units, *hit.seat, *req);
    if (v.kind == listener::Verdict::Kind::Silent) return 0;
    std::size_t n = 0;
    if (v.kind == listener::Verdict::Kind::Exception) {
        // FATEK's error code is one character: codes up to Fh as they are, larger ones as F.
        Reply reply(out.data(), hit.answer_as, req->command.data());
        reply.put(static_cast<std::uint8_t>("0123456789ABCDEF"[std::min<unsigned>(v.code, 0xF)]));
        n = reply.finish();
    } else {
        n = execute(*hit.seat, hit.answer_as, read_only, *req, out.data());
    }
    // A wrong checksum: its first digit changed to another hex digit.
    if (v.fate.garble == listener::Garble::Crc && n >= 3)
        out[n - 3] = out[n - 3] == '0' ? '1' : '0';
    units.fate() = v.fate;
    if (hit.seat->traffic != nullptr && units.serving() != nullptr) {
        // The PLC's traffic: the command and the error code of the reply (its sixth character;
        // 4E has none).
        listener::Exchange e;
        e.at = std::chrono::system_clock::now();
        e.client = units.serving()->id;
        e.protocol = units.serving()->protocol;
        e.unit = req->station;
        e.function = req->code.value_or(0);
        // The code as a number (the sixth character is its hex digit: '4', 'A').
        if (req->code != 0x4E && n > 6 && hex_digit(out[5]) > 0)
            e.error = static_cast<std::uint8_t>(hex_digit(out[5]));
        try {
            hit.seat->traffic->record(*units.serving(), e);
        } catch (const std::bad_alloc&) {
            // Answered all the same; only its line in the traffic is lost.
        }
    }
    return v.drop ? 0 : n;
}

}  // namespace plcemu::fatek
