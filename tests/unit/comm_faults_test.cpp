// Communication faults (docs/communication-faults.md): what listener::CommFaults makes of a
// request, the settings' refusals and names, and the `faults:` section of a config.

#include <gtest/gtest.h>

#include <set>

#include "plcemu/config/comm_faults.hpp"
#include "plcemu/config/config.hpp"
#include "plcemu/listener/comm_faults.hpp"
#include "support/config_errors.hpp"
#include "support/log_capture.hpp"
#include "support/profiles.hpp"

namespace plcemu::listener {
namespace {

using config::CommFaultSettings;
using image::Area;
using image::Range;

Asked asked(std::uint8_t unit = 1,
            std::uint8_t function = 3,
            Carrier carrier = Carrier::Stream,
            std::uint64_t client = 1) {
    Asked a;
    a.unit = unit;
    a.function = function;
    a.carrier = carrier;
    a.client = client;
    return a;
}

CommFaults with(const CommFaultSettings& s) {
    CommFaults f("", &testing::fbs_naming());
    f.set(s);
    return f;
}

TEST(CommFaults, NoFaultServesEverything) {
    CommFaults f;
    EXPECT_FALSE(f.active());
    const Verdict v = f.judge(asked());
    EXPECT_EQ(v.kind, Verdict::Kind::Serve);
    EXPECT_FALSE(v.drop);
    EXPECT_TRUE(v.fate.none());
}

TEST(CommFaults, OfflineSilencesAndNothingElseApplies) {
    CommFaultSettings s;
    s.offline = true;
    s.exception = 4;
    s.delay_min_ms = s.delay_max_ms = 100;
    auto f = with(s);
    const Verdict v = f.judge(asked());
    EXPECT_EQ(v.kind, Verdict::Kind::Silent);
    EXPECT_TRUE(v.fate.none());
    EXPECT_EQ(f.figures().silenced, 1u);
}

TEST(CommFaults, ExceptionRefusesWithItsCode) {
    CommFaultSettings s;
    s.exception = 0x0B;
    auto f = with(s);
    const Verdict v = f.judge(asked());
    EXPECT_EQ(v.kind, Verdict::Kind::Exception);
    EXPECT_EQ(v.code, 0x0B);
}

TEST(CommFaults, DropEveryNthMatchingRequest) {
    CommFaultSettings s;
    s.drop_every = 3;
    auto f = with(s);
    std::vector<bool> dropped;
    for (int i = 0; i < 7; ++i) dropped.push_back(f.judge(asked()).drop);
    EXPECT_EQ(dropped, (std::vector<bool>{false, false, true, false, false, true, false}));
    // Switching again counts afresh.
    f.set(s);
    EXPECT_FALSE(f.judge(asked()).drop);
}

TEST(CommFaults, DropProbabilityIsSeededAndRepeatsAfterASwitch) {
    CommFaultSettings s;
    s.drop_probability = 0.5;
    s.seed = 42;
    auto f = with(s);
    std::vector<bool> first;
    for (int i = 0; i < 200; ++i) first.push_back(f.judge(asked()).drop);
    const auto n = std::count(first.begin(), first.end(), true);
    EXPECT_GT(n, 60);
    EXPECT_LT(n, 140);
    f.set(s);
    std::vector<bool> again;
    for (int i = 0; i < 200; ++i) again.push_back(f.judge(asked()).drop);
    EXPECT_EQ(first, again);
    s.seed = 43;
    f.set(s);
    std::vector<bool> other;
    for (int i = 0; i < 200; ++i) other.push_back(f.judge(asked()).drop);
    EXPECT_NE(first, other);
}

TEST(CommFaults, DelayIsFixedOrDrawnWithinItsBounds) {
    CommFaultSettings s;
    s.delay_min_ms = s.delay_max_ms = 300;
    auto f = with(s);
    EXPECT_EQ(f.judge(asked()).fate.delay, std::chrono::milliseconds(300));
    s.delay_min_ms = 100;
    s.seed = 5;
    f.set(s);
    std::set<long> seen;
    std::vector<long> first;
    for (int i = 0; i < 100; ++i) {
        const long ms = f.judge(asked()).fate.delay.count();
        EXPECT_GE(ms, 100);
        EXPECT_LE(ms, 300);
        seen.insert(ms);
        first.push_back(ms);
    }
    EXPECT_GT(seen.size(), 20u);
    f.set(s);
    for (int i = 0; i < 100; ++i) EXPECT_EQ(f.judge(asked()).fate.delay.count(), first[i]);
}

TEST(CommFaults, DisconnectAfterNRequestsOfAConnection) {
    CommFaultSettings s;
    s.disconnect_after = 2;
    auto f = with(s);
    EXPECT_EQ(f.judge(asked(1, 3, Carrier::Stream, 7)).fate.close, Fate::Close::No);
    EXPECT_EQ(f.judge(asked(1, 3, Carrier::Stream, 8)).fate.close, Fate::Close::No);
    const Verdict second = f.judge(asked(1, 3, Carrier::Stream, 7));
    EXPECT_EQ(second.fate.close, Fate::Close::Fin);
    EXPECT_FALSE(second.drop);  // the Nth is answered, then closed
    // Another connection counts its own; a client gone forgets its count.
    f.client_gone(8);
    EXPECT_EQ(f.judge(asked(1, 3, Carrier::Stream, 8)).fate.close, Fate::Close::No);
    // UDP and serial lines have no connection to close.
    EXPECT_EQ(f.judge(asked(1, 3, Carrier::Datagram, 9)).fate.close, Fate::Close::No);
    EXPECT_EQ(f.judge(asked(1, 3, Carrier::Datagram, 9)).fate.close, Fate::Close::No);
    EXPECT_EQ(f.figures().disconnected, 1u);
}

TEST(CommFaults, DisconnectAtOnceClosesWithoutAnAnswerAndResetSaysRst) {
    CommFaultSettings s;
    s.disconnect_after = 0;
    s.reset = true;
    auto f = with(s);
    const Verdict v = f.judge(asked());
    EXPECT_TRUE(v.drop);
    EXPECT_EQ(v.fate.close, Fate::Close::Reset);
    // On a serial line the request is served as usual.
    const Verdict line = f.judge(asked(1, 3, Carrier::Line));
    EXPECT_FALSE(line.drop);
    EXPECT_EQ(line.fate.close, Fate::Close::No);
}

TEST(CommFaults, GarbleOnlyOnSerialLines) {
    CommFaultSettings s;
    s.garble = config::Garble::Crc;
    auto f = with(s);
    EXPECT_EQ(f.judge(asked(1, 3, Carrier::Line)).fate.garble, config::Garble::Crc);
    EXPECT_EQ(f.judge(asked(1, 3, Carrier::Stream)).fate.garble, config::Garble::None);
    EXPECT_EQ(f.judge(asked(1, 3, Carrier::Datagram)).fate.garble, config::Garble::None);
}

TEST(CommFaults, ScopeByUnitFunctionAndDevices) {
    CommFaultSettings s;
    s.exception = 4;
    s.unit = 2;
    s.function = 3;
    s.devices = Range{Area::R, 100, 10};
    auto f = with(s);
    Asked a = asked(2, 3);
    a.devices = Range{Area::R, 105, 2};
    EXPECT_EQ(f.judge(a).kind, Verdict::Kind::Exception);
    a.devices = Range{Area::R, 0, 2};  // R0: served
    EXPECT_EQ(f.judge(a).kind, Verdict::Kind::Serve);
    a.also = Range{Area::R, 109, 1};  // FC17h's write range reaches R109
    EXPECT_EQ(f.judge(a).kind, Verdict::Kind::Exception);
    a = asked(1, 3);  // another unit
    a.devices = Range{Area::R, 100, 1};
    EXPECT_EQ(f.judge(a).kind, Verdict::Kind::Serve);
    a = asked(2, 4);  // another function
    a.devices = Range{Area::R, 100, 1};
    EXPECT_EQ(f.judge(a).kind, Verdict::Kind::Serve);
    a = asked(2, 3);  // no devices named (FATEK, FC08): left alone
    EXPECT_EQ(f.judge(a).kind, Verdict::Kind::Serve);
    a.devices = Range{Area::D, 100, 1};  // another area
    EXPECT_EQ(f.judge(a).kind, Verdict::Kind::Serve);
}

TEST(CommFaults, StopTellsTheRunSwitchOnlyWhenItChanges) {
    CommFaults f;
    std::vector<bool> told;
    f.on_stop([&](bool stop) { told.push_back(stop); });
    CommFaultSettings s;
    s.stop = true;
    f.set(s);
    s.delay_min_ms = s.delay_max_ms = 10;
    f.set(s);  // stop unchanged
    f.clear();
    EXPECT_EQ(told, (std::vector<bool>{true, false}));
}

TEST(CommFaults, EverySwitchIsLoggedOnce) {
    testing::LogCapture log("comm");
    CommFaults f("kiln: ", &testing::fbs_naming());
    CommFaultSettings s;
    s.delay_min_ms = s.delay_max_ms = 300;
    s.devices = Range{Area::R, 100, 10};
    f.set(s);
    s.exception = 6;
    f.set(s);
    f.set(s);  // nothing switched
    f.clear();
    EXPECT_EQ(log.count("kiln: comm fault on: delay 300 ms (R100-R109)"), 1u) << log.log();
    EXPECT_EQ(log.count("kiln: comm fault on: exception 06h (R100-R109)"), 1u) << log.log();
    EXPECT_EQ(log.count("comm fault off: delay 300 ms"), 1u) << log.log();
    EXPECT_EQ(log.count("comm fault off: exception 06h"), 1u) << log.log();
    EXPECT_EQ(log.count("comm fault"), 4u) << log.log();
}

TEST(CommFaults, CutOrPauseSpoilsWhatNeedsNoFraming) {
    Fate f;
    f.garble = config::Garble::Short;
    EXPECT_EQ(cut_or_pause(f, 9, std::chrono::microseconds(0)), 4u);
    f = {};
    f.garble = config::Garble::Gap;
    EXPECT_EQ(cut_or_pause(f, 9, std::chrono::microseconds(2500)), 9u);
    EXPECT_EQ(f.gap_at, 4u);
    EXPECT_EQ(f.gap, std::chrono::microseconds(2500));
}

}  // namespace
}  // namespace plcemu::listener

namespace plcemu::config {
namespace {

TEST(CommFaultSettings, RefusalsNameTheField) {
    CommFaultSettings s;
    EXPECT_EQ(comm_fault_refusal(s), "");
    s.delay_min_ms = 300;
    s.delay_max_ms = 100;
    EXPECT_NE(comm_fault_refusal(s).find("delay_ms"), std::string::npos);
    s = {};
    s.drop_every = 2;
    s.drop_probability = 0.5;
    EXPECT_NE(comm_fault_refusal(s).find("drop_probability: drop_every is set too"),
              std::string::npos);
    s = {};
    s.drop_probability = 1.5;
    EXPECT_NE(comm_fault_refusal(s).find("drop_probability"), std::string::npos);
    s = {};
    s.reset = true;
    EXPECT_NE(comm_fault_refusal(s).find("reset"), std::string::npos);
    s = {};
    s.delay_min_ms = s.delay_max_ms = kMaxCommDelayMs + 1;
    EXPECT_NE(comm_fault_refusal(s).find("delay_ms"), std::string::npos);
}

TEST(CommFaultSettings, RangeFromADeviceNameAndACount) {
    const auto& n = testing::fbs_naming();
    EXPECT_EQ(comm_fault_range(n, "R100", 10), (image::Range{image::Area::R, 100, 10}));
    // WM800, 2 words: the 32 bits M800-M831.
    EXPECT_EQ(comm_fault_range(n, "WM800", 2), (image::Range{image::Area::M, 800, 32}));
    EXPECT_FALSE(comm_fault_range(n, "Q5", 1));
    EXPECT_FALSE(comm_fault_range(n, "R100", 0));
    EXPECT_FALSE(comm_fault_range(n, "<script>", 1));
}

TEST(CommFaultSettings, LinesAndScopeInWords) {
    CommFaultSettings s;
    EXPECT_TRUE(comm_fault_lines(s).empty());
    EXPECT_FALSE(s.any());
    s.unit = 2;  // a scope alone switches nothing on
    EXPECT_FALSE(s.any());
    s.drop_every = 2;
    s.disconnect_after = 0;
    s.garble = Garble::Gap;
    EXPECT_TRUE(s.any());
    EXPECT_EQ(comm_fault_lines(s),
              (std::vector<std::string>{"drop every 2nd request", "disconnect at once (FIN)",
                                        "garble gap"}));
    s.function = 0x10;
    s.devices = image::Range{image::Area::D, 0, 4};
    EXPECT_EQ(comm_fault_scope(s, testing::fbs_naming()), "unit 2, function 10h, D0-D3");
    EXPECT_EQ(garble_named("crc"), Garble::Crc);
    EXPECT_FALSE(garble_named("CRC"));
}

TEST(ConfigFaults, TheSectionReadsEveryField) {
    const Config c = parse_config(
        "profile: fbs\n"
        "faults:\n"
        "  delay_ms: [100, 300]\n"
        "  seed: 7\n"
        "  exception: 0x0B\n"
        "  disconnect_after: 3\n"
        "  reset: true\n"
        "  garble: short\n"
        "  stop: true\n"
        "  unit: 2\n"
        "  function: 3\n"
        "  from: R100\n"
        "  count: 10\n",
        "t.yaml");
    EXPECT_EQ(c.faults.delay_min_ms, 100u);
    EXPECT_EQ(c.faults.delay_max_ms, 300u);
    EXPECT_EQ(c.faults.seed, 7u);
    EXPECT_EQ(c.faults.exception, 0x0B);
    EXPECT_EQ(c.faults.disconnect_after, 3u);
    EXPECT_TRUE(c.faults.reset);
    EXPECT_EQ(c.faults.garble, Garble::Short);
    EXPECT_TRUE(c.faults.stop);
    EXPECT_EQ(c.faults.unit, 2);
    EXPECT_EQ(c.faults.function, 3);
    EXPECT_EQ(c.faults.devices, (image::Range{image::Area::R, 100, 10}));
    EXPECT_FALSE(parse_config("profile: fbs\n", "t.yaml").faults.any());
}

TEST(ConfigFaults, ErrorsNameLineAndColumn) {
    const auto one = [](const std::string& text) {
        return testing::config_failure([&] { parse_config(text, "t.yaml"); });
    };
    testing::expect_config_errors(one("profile: fbs\nfaults: {drop_probability: 2}\n"), "t.yaml",
                                  {{2, 28, "faults.drop_probability"}});
    testing::expect_config_errors(one("profile: fbs\nfaults: {from: Q5}\n"), "t.yaml",
                                  {{2, 16, "faults.from: expected a device such as R100"}});
    testing::expect_config_errors(one("profile: fbs\nfaults: {reset: true}\n"), "t.yaml",
                                  {{2, 17, "faults.reset"}});
    testing::expect_config_errors(one("profile: fbs\nfaults: {dleay_ms: 3}\n"), "t.yaml",
                                  {{2, 10, "unknown key 'dleay_ms'"}});
    testing::expect_config_errors(one("profile: fbs\nfaults: {delay_ms: [300, 100]}\n"), "t.yaml",
                                  {{2, 20, "faults.delay_ms: expected [min, max]"}});
    testing::expect_config_errors(one("profile: fbs\nfaults: {from: R9000}\n"), "t.yaml",
                                  {{2, 16, "faults.from: R9000"}});
}

}  // namespace
}  // namespace plcemu::config
