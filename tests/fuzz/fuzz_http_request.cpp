// libFuzzer harness: an HTTP connection's byte stream into the console and REST API
// (docs/console.md).
//
// Input: the bytes a client sends. The stream is cut as the HTTP session cuts it, every request
// is read and answered by the router on an FBs PLC (with time control), and an events request's
// subscription is polled once.
//
// Invariants: the cutter never gives up on the stream and cuts only what was received; it cuts
// the same whether the bytes come at once or a few at a time, as a connection reads them; a
// request that cannot be read is refused with 400, 413, 431 or 501; every answer is a 2xx, 4xx
// or an event stream — never a 5xx — and its JSON body parses.

#include <nlohmann/json.hpp>

#include <algorithm>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <span>
#include <string>
#include <vector>

#include "http/message.hpp"
#include "http/router.hpp"
#include "plcemu/daemon/plc.hpp"
#include "support/fake_time.hpp"
#include "support/fatek_rig.hpp"

using namespace plcemu;

namespace {

void check(bool ok, const char* what, std::span<const std::uint8_t> req, const std::string& rep) {
    if (ok) return;
    std::fprintf(stderr, "invariant broken: %s\n  request: %.*s\n  answer: %s\n", what,
                 static_cast<int>(req.size()), reinterpret_cast<const char*>(req.data()),
                 rep.c_str());
    std::abort();
}

// One FBs PLC seated on an HTTP listener's unit table; reset() puts it back as built.
struct Rig {
    Rig()
        : plc(config::parse_config("profile: fbs\nmodbus: {write_protect: [R200-R209]}\n",
                                   "fuzz.yaml")),
          time(plc.engine()) {
        time.max_step = 2;  // a step request runs at most two scans here
        listener::Seat s = testing::seat_of(plc);
        s.id = "kiln";
        s.time = &time;
        units.assign({s});
        const auto st = plc.image().storage();
        image.assign(st.begin(), st.end());
        for (int c = 0; c < plant::kChannels; ++c) params.push_back(plc.plant().params(c));
    }
    void reset() {
        const auto st = plc.image().storage();
        std::copy(image.begin(), image.end(), st.begin());
        for (int c = 0; c < plant::kChannels; ++c) {
            plc.plant().set_params(c, params[static_cast<std::size_t>(c)]);
            plc.plant().set_faults(c, {});
        }
        time.set_frozen(false);
        time.set_time_scale(1);
    }
    daemon::Plc plc;
    testing::FakeTime time;
    listener::UnitTable units;
    std::vector<std::byte> image;
    std::vector<plant::ChannelParams> params;
};

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    static Rig rig;
    rig.reset();
    // The first byte chooses the listener's settings: a token, read-only.
    if (size > 0) {
        rig.units.set_token((data[0] & 1) != 0 ? "s3cret" : "");
        rig.units.set_read_only((data[0] & 2) != 0);
        ++data;
        --size;
    }
    std::span<const std::uint8_t> stream(data, size);
    http::RequestCutter cutter;
    for (int served = 0; !stream.empty() && served < 8; ++served) {
        const listener::Split s = cutter.split(stream);
        check(s.cut != listener::Cut::Bad, "the cutter gave up on the stream", stream, "");
        // The same stream read 7 bytes at a time, by a cutter of its own.
        http::RequestCutter reads;
        listener::Split few;
        int continues = 0;  // a "100 Continue" is due once a request at most
        for (std::size_t n = 0; n < stream.size() && few.cut == listener::Cut::Incomplete;) {
            n = std::min(n + 7, stream.size());
            few = reads.split(stream.first(n));
            if (few.cut == listener::Cut::Incomplete && reads.take_continue()) ++continues;
        }
        check(continues <= 1, "more than one 100 Continue for a request", stream, "");
        // Beast reads the head's lines as far as they go on its first bytes, and after that waits
        // for the head's end: read a few bytes at a time, a bad line may be found only there.
        http::Request rq;
        http::Refusal refusal;
        const bool read = s.cut == listener::Cut::Frame && cutter.take(rq, refusal);
        check(few.cut == s.cut ||
                  (few.cut == listener::Cut::Incomplete && s.cut == listener::Cut::Frame && !read),
              "a cut that depends on how the bytes arrive", stream, "");
        if (s.cut == listener::Cut::Incomplete) break;
        check(s.size >= 1 && s.size <= stream.size(), "impossible frame size", stream, "");
        const auto frame = stream.first(s.size);
        stream = stream.subspan(s.size);
        cutter.next();
        if (!read) {
            check(refusal.status == 400 || refusal.status == 413 || refusal.status == 431 ||
                      refusal.status == 501,
                  "a refusal that is not 400, 413, 431 or 501", frame, refusal.why);
            // Read a few bytes at a time, the request is refused alike (when it is cut yet).
            http::Request again;
            http::Refusal early;
            check(few.cut == listener::Cut::Incomplete ||
                      (few.size <= s.size && !reads.take(again, early) &&
                       early.status == refusal.status),
                  "a refusal that depends on how the bytes arrive", frame, early.why);
            break;  // the connection is closed after it
        }
        check(few.size == s.size, "a request cut elsewhere when read a few bytes at a time", frame,
              "");
        http::Routed routed = http::route(rq, rig.units);
        if (routed.stream) {
            bool ended = false;
            const std::string events = routed.stream->poll(rig.units, ended);
            check(events.rfind("event: ", 0) == 0, "an event stream without an event", frame,
                  events);
            continue;
        }
        const http::Response& r = routed.response;
        check(r.status >= 200 && r.status < 500, "an answer that is not 2xx or 4xx", frame, r.body);
        if (r.content_type == "application/json") {
            check(!nlohmann::json::parse(r.body, nullptr, false).is_discarded(),
                  "a JSON answer that does not parse", frame, r.body);
        }
        check(!http::serialize(r, rq.keep_alive).empty(), "an empty response", frame, r.body);
    }
    return 0;
}
