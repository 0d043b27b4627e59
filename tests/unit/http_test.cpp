// The HTTP side (docs/console.md): requests cut from a byte stream and read (Boost.Beast), and
// the REST API's answers and refusals, on a PLC built from config text. The system tests
// (tests/system/test_http_api.py) drive the same through the daemon's sockets.

#include <gtest/gtest.h>

#include <algorithm>
#include <fstream>
#include <iterator>
#include <nlohmann/json.hpp>
#include <string>

#include "http/message.hpp"
#include "http/router.hpp"
#include "support/fake_time.hpp"
#include "support/fatek_rig.hpp"
#include "support/plc_rig.hpp"

namespace plcemu::testing {
namespace {

using http::Refusal;
using http::Request;
using listener::Cut;

std::span<const std::uint8_t> bytes(const std::string& s) {
    return {reinterpret_cast<const std::uint8_t*>(s.data()), s.size()};
}

TEST(HttpMessage, ARequestIsWholeOnlyWithItsBody) {
    const std::string put =
        "PUT /api/v1/plcs/0/devices/R1 HTTP/1.1\r\nHost: 127.0.0.1\r\nContent-Type: "
        "application/json\r\n"
        "Content-Length: 14\r\n\r\n{\"values\":[7]}";
    http::RequestCutter cutter;
    EXPECT_EQ(cutter.split(bytes(put.substr(0, 20))).cut, Cut::Incomplete);
    EXPECT_EQ(cutter.split(bytes(put.substr(0, put.size() - 1))).cut, Cut::Incomplete);
    const auto whole = cutter.split(bytes(put + "GET / HTTP/1.1\r\n"));
    ASSERT_EQ(whole.cut, Cut::Frame);
    EXPECT_EQ(whole.size, put.size());  // a pipelined request after it is not part of it
    // Asked again before the request is taken, it says the same.
    EXPECT_EQ(cutter.split(bytes(put + "GET / HTTP/1.1\r\n")).size, put.size());
    cutter.next();
    EXPECT_EQ(cutter.split(bytes("GET / HTTP/1.1\r\n")).cut, Cut::Incomplete);
    Request rq;
    Refusal no;
    ASSERT_TRUE(http::parse_request(bytes(put), rq, no));
    EXPECT_EQ(rq.method, "PUT");
    EXPECT_EQ(rq.body, "{\"values\":[7]}");
    EXPECT_EQ(rq.content_type, "application/json");
    EXPECT_TRUE(rq.keep_alive);
}

TEST(HttpMessage, TheTargetIsDecoded) {
    const std::string get =
        "GET /plcs/a%20b/devices?from=R100&count=20&x=%3Cs%3E+1 HTTP/1.1\r\n"
        "Host: 127.0.0.1\r\nConnection: close\r\n\r\n";
    Request rq;
    Refusal no;
    ASSERT_TRUE(http::parse_request(bytes(get), rq, no));
    EXPECT_EQ(rq.path, "/plcs/a b/devices");
    ASSERT_NE(rq.param("from"), nullptr);
    EXPECT_EQ(*rq.param("from"), "R100");
    EXPECT_EQ(*rq.param("x"), "<s> 1");
    EXPECT_EQ(rq.param("missing"), nullptr);
    EXPECT_FALSE(rq.keep_alive);
    Refusal r;
    EXPECT_FALSE(http::parse_request(bytes("GET /a%4 HTTP/1.1\r\nHost: 127.0.0.1\r\n\r\n"), rq, r));
    EXPECT_EQ(r.status, 400u);
}

TEST(HttpMessage, AnEncodedSlashStaysInItsSegment) {
    Request rq;
    Refusal no;
    ASSERT_TRUE(http::parse_request(
        bytes("GET /api//v1/devices/a%2Fb HTTP/1.1\r\nHost: 127.0.0.1\r\n\r\n"), rq, no));
    EXPECT_EQ(rq.path, "/api//v1/devices/a/b");
    ASSERT_EQ(rq.segments.size(), 4u);
    EXPECT_EQ(rq.segments[3], "a/b");
}

TEST(HttpMessage, WhatCannotBeReadIsAFrameThatIsRefused) {
    // Garbage: every byte buffered is one frame, so that the answer says why and ends it.
    const std::string junk = "\x01\x02 not http\r\n\r\n";
    http::RequestCutter cutter;
    const auto s = cutter.split(bytes(junk));
    ASSERT_EQ(s.cut, Cut::Frame);
    EXPECT_EQ(s.size, junk.size());
    Request rq;
    Refusal r;
    EXPECT_FALSE(http::parse_request(bytes(junk), rq, r));
    EXPECT_EQ(r.status, 400u);
    // A body over the limit is refused from its Content-Length, before it arrives.
    const std::string big = "PUT / HTTP/1.1\r\nHost: 127.0.0.1\r\nContent-Length: " +
                            std::to_string(http::kMaxBody + 1) + "\r\n\r\n";
    cutter.next();
    ASSERT_EQ(cutter.split(bytes(big)).cut, Cut::Frame);
    EXPECT_FALSE(http::parse_request(bytes(big), rq, r));
    EXPECT_EQ(r.status, 413u);
    const std::string head =
        "GET / HTTP/1.1\r\nX: " + std::string(http::kMaxHead, 'a') + "\r\n\r\n";
    cutter.next();
    ASSERT_EQ(cutter.split(bytes(head)).cut, Cut::Frame);
    EXPECT_FALSE(http::parse_request(bytes(head), rq, r));
    EXPECT_EQ(r.status, 431u);
    // HTTP/1.1 requires a Host (RFC 9112 §3.2); HTTP/1.0 has none to require.
    EXPECT_FALSE(http::parse_request(bytes("GET /healthz HTTP/1.1\r\n\r\n"), rq, r));
    EXPECT_EQ(r.status, 400u);
    EXPECT_NE(r.why.find("without a Host"), std::string::npos) << r.why;
    Refusal no;
    EXPECT_TRUE(http::parse_request(bytes("GET /healthz HTTP/1.0\r\n\r\n"), rq, no)) << no.why;
}

// Each byte is read once: a request sent a byte at a time costs the loop what it costs in one
// piece. The cutter does not go back over the bytes it has taken (here changed behind its back,
// which a connection never does): a parser started over would find no request in them.
TEST(HttpMessage, TheCutterReadsEachByteOnce) {
    const std::string put =
        "PUT /api/v1/plcs/0/devices/R1 HTTP/1.1\r\nHost: 127.0.0.1\r\nContent-Type: "
        "application/json\r\nContent-Length: 14\r\n\r\n{\"values\":[7]}";
    const std::size_t head = put.find("\r\n\r\n") + 4;
    http::RequestCutter cutter;
    for (std::size_t n = 1; n < put.size(); ++n) {
        ASSERT_EQ(cutter.split(bytes(put.substr(0, n))).cut, Cut::Incomplete) << n;
    }
    std::string changed = put;
    std::fill_n(changed.begin(), head + 3, '\x01');
    const auto s = cutter.split(bytes(changed));
    ASSERT_EQ(s.cut, Cut::Frame);
    EXPECT_EQ(s.size, put.size());
    // Given fewer bytes than it took, it starts over rather than cut where no request ends.
    EXPECT_EQ(cutter.split(bytes(put.substr(0, 10))).cut, Cut::Incomplete);
    EXPECT_EQ(cutter.split(bytes(put)).size, put.size());
}

TEST(HttpMessage, AResponseSaysItsLengthAndNoCaching) {
    http::Response r;
    r.body = "{}";
    const std::string s = http::serialize(r, true);
    EXPECT_NE(s.find("HTTP/1.1 200 OK\r\n"), std::string::npos);
    EXPECT_NE(s.find("Content-Length: 2\r\n"), std::string::npos);
    EXPECT_NE(s.find("Cache-Control: no-store\r\n"), std::string::npos);
    EXPECT_EQ(s.find("Access-Control"), std::string::npos);  // no CORS
    const std::string head = http::serialize(r, false, true);
    EXPECT_NE(head.find("Connection: close\r\n"), std::string::npos);
    EXPECT_EQ(head.substr(head.size() - 4), "\r\n\r\n");  // HEAD: no body
}

// A PLC on a listener's unit table, as the daemon seats it.
struct ApiRig : PlcRig {
    explicit ApiRig(const std::string& extra = "")
        : PlcRig("profile: fbs\nmodbus: {write_protect: [R200-R209]}\n" + extra, "api.yaml") {
        listener::Seat s = seat_of(plc);
        s.time = &time;
        units.assign({s});
    }

    http::Response call(const std::string& method,
                        const std::string& target,
                        const std::string& body = "",
                        const std::string& headers = "Content-Type: application/json\r\n") {
        const bool own_host = headers.find("Host:") != std::string::npos;
        const std::string raw =
            method + " " + target + " HTTP/1.1\r\n" + (own_host ? "" : "Host: 127.0.0.1\r\n") +
            headers + "Content-Length: " + std::to_string(body.size()) + "\r\n\r\n" + body;
        Request rq;
        Refusal no;
        EXPECT_TRUE(http::parse_request(bytes(raw), rq, no)) << no.why;
        return http::route(rq, units).response;
    }

    FakeTime time{plc.engine()};
    listener::UnitTable units;
};

TEST(HttpApi, DevicesAreReadAndWrittenByTheFamilysNames) {
    ApiRig rig;
    rig.set_r(100, 1500);
    rig.set_r(101, -2);
    auto r = rig.call("GET", "/api/v1/plcs/0/devices/R100?count=2");
    EXPECT_EQ(r.status, 200u);
    EXPECT_EQ(r.body,
              "{\"bits\":false,\"device\":\"R100\",\"names\":[\"R100\",\"R101\"],\"values\":"
              "[1500,65534],\"words\":[1,1]}\n");
    r = rig.call("PUT", "/api/v1/plcs/0/devices/R100", "{\"values\":[-1, 7]}");
    EXPECT_EQ(r.status, 200u) << r.body;
    EXPECT_EQ(rig.r(100), 65535);
    EXPECT_EQ(rig.r(101), 7);
    r = rig.call("PUT", "/api/v1/plcs/0/devices/M10", "{\"values\":[true, 0, 1]}");
    EXPECT_EQ(r.status, 200u) << r.body;
    EXPECT_TRUE(rig.m(10));
    EXPECT_FALSE(rig.m(11));
    EXPECT_TRUE(rig.m(12));
    // WM800: 16 bits as one word, low bit M800.
    r = rig.call("PUT", "/api/v1/plcs/0/devices/WM800", "{\"values\":[5]}");
    EXPECT_EQ(r.status, 200u) << r.body;
    EXPECT_TRUE(rig.m(800));
    EXPECT_FALSE(rig.m(801));
    EXPECT_TRUE(rig.m(802));
}

TEST(HttpApi, AWriteThePlcWouldRefuseIsRefusedWithTheReasonAndWritesNothing) {
    ApiRig rig;
    auto r = rig.call("PUT", "/api/v1/plcs/0/devices/R199", "{\"values\":[1, 2]}");
    EXPECT_EQ(r.status, 403u);
    EXPECT_NE(r.body.find("R200-R209 may not be written"), std::string::npos) << r.body;
    EXPECT_EQ(rig.r(199), 0);
    r = rig.call("PUT", "/api/v1/plcs/0/devices/R1", "{\"values\":[65536]}");
    EXPECT_EQ(r.status, 400u);
    r = rig.call("PUT", "/api/v1/plcs/0/devices/M1", "{\"values\":[2]}");
    EXPECT_EQ(r.status, 400u);
    r = rig.call("PUT", "/api/v1/plcs/0/devices/R1", "{\"values\":[\"1\"]}");
    EXPECT_EQ(r.status, 400u);
    r = rig.call("PUT", "/api/v1/plcs/0/devices/R1", "[1]");
    EXPECT_EQ(r.status, 400u);
    r = rig.call("PUT", "/api/v1/plcs/0/devices/R1", "{\"values\":[1]}",
                 "Content-Type: text/plain\r\n");
    EXPECT_EQ(r.status, 415u);
    EXPECT_EQ(rig.r(1), 0);
    EXPECT_EQ(rig.call("GET", "/api/v1/plcs/0/devices/Q1").status, 404u);
    EXPECT_EQ(rig.call("GET", "/api/v1/plcs/7/devices/R1").status, 404u);
    EXPECT_EQ(rig.call("GET", "/api/v1/plcs/0/devices/R1?count=0").status, 400u);
    EXPECT_EQ(rig.call("GET", "/api/v1/plcs/0/devices/R1?count=1001").status, 400u);
    r = rig.call("GET", "/api/v1/plcs/0/devices/R8000?count=1000");
    EXPECT_EQ(r.status, 400u);
    EXPECT_NE(r.body.find("R8000 and the 999 after it (R8000-R8999) go past the last R, R8071"),
              std::string::npos)
        << r.body;
    // One device of 16 bits runs past as well (it was "WM1990 and the 0 after it go past").
    r = rig.call("GET", "/api/v1/plcs/0/devices/WM1990");
    EXPECT_EQ(r.status, 400u);
    EXPECT_NE(r.body.find("WM1990 (M1990-M2005) goes past the last M, M2001"), std::string::npos)
        << r.body;
    r = rig.call("DELETE", "/api/v1/plcs/0/devices/R1");
    EXPECT_EQ(r.status, 405u);
    ASSERT_FALSE(r.headers.empty());
    EXPECT_EQ(r.headers.front().first, "Allow");
}

TEST(HttpApi, AHostThatIsNotTheConsolesIsRefused) {
    ApiRig rig;
    // DNS rebinding: a page of evil.example whose name now resolves to this address.
    auto r = rig.call("GET", "/api/v1/plcs", "", "Host: evil.example:8020\r\n");
    EXPECT_EQ(r.status, 421u);
    EXPECT_NE(r.body.find("evil.example"), std::string::npos);
    r = rig.call("PUT", "/api/v1/plcs/0/devices/R1", "{\"values\":[1]}",
                 "Host: evil.example\r\nContent-Type: application/json\r\n");
    EXPECT_EQ(r.status, 421u);
    EXPECT_EQ(rig.r(1), 0);
    for (const char* host : {"127.0.0.1:8020", "LocalHost:8020", "[::1]:8020", "10.0.0.2"}) {
        EXPECT_EQ(rig.call("GET", "/api/v1/plcs", "", std::string("Host: ") + host + "\r\n").status,
                  200u)
            << host;
    }
    rig.units.set_hosts({"gateway.example"});
    EXPECT_EQ(rig.call("GET", "/api/v1/plcs", "", "Host: Gateway.Example:8020\r\n").status, 200u);
}

TEST(HttpApi, TheTokenAndReadOnlyGuardEveryWrite) {
    ApiRig rig;
    rig.units.set_token("s3cret");
    auto r = rig.call("PUT", "/api/v1/plcs/0/devices/R1", "{\"values\":[1]}");
    EXPECT_EQ(r.status, 401u);
    r = rig.call("PUT", "/api/v1/plcs/0/devices/R1", "{\"values\":[1]}",
                 "Content-Type: application/json\r\nAuthorization: Bearer s3cre\r\n");
    EXPECT_EQ(r.status, 401u);
    EXPECT_EQ(rig.r(1), 0);
    r = rig.call("PUT", "/api/v1/plcs/0/devices/R1", "{\"values\":[1]}",
                 "Content-Type: application/json\r\nAuthorization: Bearer s3cret\r\n");
    EXPECT_EQ(r.status, 200u);
    EXPECT_EQ(rig.r(1), 1);
    // Reading needs no token.
    EXPECT_EQ(rig.call("GET", "/api/v1/plcs/0/devices/R1").status, 200u);
    rig.units.set_read_only(true);
    r = rig.call("PUT", "/api/v1/plcs/0/devices/R1", "{\"values\":[2]}",
                 "Content-Type: application/json\r\nAuthorization: Bearer s3cret\r\n");
    EXPECT_EQ(r.status, 403u);
    EXPECT_EQ(rig.r(1), 1);
}

TEST(HttpApi, TheSimulatorTakesItsChangesWholeOrNotAtAll) {
    ApiRig rig;
    // Channel 2's tau is out of range: channel 1's fault is not applied either.
    auto r = rig.call("PUT", "/api/v1/plcs/0/simulator",
                      "{\"channels\":[{\"channel\":1,\"faults\":{\"heater_open\":true}},"
                      "{\"channel\":2,\"tau_s\":0}]}");
    EXPECT_EQ(r.status, 400u) << r.body;
    EXPECT_FALSE(rig.plc.plant().faults(1).heater_open);
    r = rig.call("PUT", "/api/v1/plcs/0/simulator", "{\"frozen\":true,\"step\":3,\"bogus\":1}");
    EXPECT_EQ(r.status, 400u);
    EXPECT_TRUE(rig.time.steps.empty());
    r = rig.call("PUT", "/api/v1/plcs/0/simulator",
                 "{\"frozen\":true,\"step\":3,\"time_scale\":20,"
                 "\"channels\":[{\"channel\":1,\"faults\":{\"heater_open\":true}}]}");
    EXPECT_EQ(r.status, 200u) << r.body;
    EXPECT_TRUE(rig.plc.plant().faults(1).heater_open);
    EXPECT_TRUE(rig.time.frozen());
    EXPECT_EQ(rig.time.scale, 20.0);
    ASSERT_EQ(rig.time.steps.size(), 1u);
    EXPECT_EQ(rig.time.steps[0], 3u);
    EXPECT_EQ(rig.plc.engine().scans(), 3u);
    EXPECT_NE(r.body.find("\"heater_open\":true"), std::string::npos);
}

// A PLC of one of config/'s files, seated as the daemon seats it.
struct FileRig {
    explicit FileRig(const std::string& name)
        : rig(read(name), name) {
        listener::Seat s = seat_of(rig.plc);
        units.assign({s});
    }
    static std::string read(const std::string& name) {
        std::ifstream in(std::string(PLCEMU_SOURCE_DIR) + "/config/" + name);
        return {std::istreambuf_iterator<char>(in), {}};
    }
    http::Response get(const std::string& target) {
        const std::string raw = "GET " + target + " HTTP/1.1\r\nHost: 127.0.0.1\r\n\r\n";
        Request rq;
        Refusal no;
        EXPECT_TRUE(http::parse_request(bytes(raw), rq, no));
        return http::route(rq, units).response;
    }
    PlcRig rig;
    listener::UnitTable units;
};

TEST(HttpLoops, TheTpctlPointsOfTheFbsExampleAreItsLoops) {
    FileRig f("default.yaml");
    f.rig.scan(5);
    f.rig.set_r(103, 1234);  // point 3's set point, 123.4 degC
    const auto r = f.get("/api/v1/plcs/0/loops");
    ASSERT_EQ(r.status, 200u);
    const auto j = nlohmann::json::parse(r.body);
    ASSERT_EQ(j["loops"].size(), 10u);  // TPCTL points 0-9
    const auto& p3 = j["loops"][3];
    EXPECT_EQ(p3["name"], "TPCTL point 3 (channel 3)");
    EXPECT_EQ(p3["channel"], 3);
    EXPECT_EQ(p3["sv"]["device"], "R103");
    EXPECT_DOUBLE_EQ(p3["sv"]["value"].get<double>(), 123.4);
    EXPECT_EQ(p3["output"]["device"], "R203");
    EXPECT_EQ(p3["output_full"], 16383);
    EXPECT_EQ(p3["parameters"][0]["name"], "Kc");
    EXPECT_EQ(p3["parameters"][0]["device"], "R123");
    EXPECT_EQ(p3["alarms"][0]["name"], "in zone");
    EXPECT_EQ(p3["alarms"][0]["device"], "R300");
    EXPECT_EQ(p3["alarms"][0]["bit"], 3);
    EXPECT_TRUE(p3.contains("true_temperature_c"));
}

TEST(HttpLoops, TheVbPidAndTpidChannelsAreLoopsWithTheirTuningSwitch) {
    FileRig pid("vb-pid.yaml");
    auto j = nlohmann::json::parse(pid.get("/api/v1/plcs/0/loops").body);
    ASSERT_EQ(j["loops"].size(), 1u);
    EXPECT_EQ(j["loops"][0]["sv"]["device"], "D100");
    EXPECT_EQ(j["loops"][0]["pv"]["device"], "D101");
    EXPECT_EQ(j["loops"][0]["output"]["device"], "D102");
    EXPECT_EQ(j["loops"][0]["tuning"]["device"], "D201");  // S3+1 b4
    EXPECT_EQ(j["loops"][0]["tuning"]["bit"], 4);
    FileRig tpid("vb-tpid.yaml");
    j = nlohmann::json::parse(tpid.get("/api/v1/plcs/0/loops").body);
    ASSERT_GE(j["loops"].size(), 1u);
    EXPECT_EQ(j["loops"][0]["output_full"], 1000);
    EXPECT_FALSE(j["loops"][0]["manual"].is_null());
}

}  // namespace
}  // namespace plcemu::testing
