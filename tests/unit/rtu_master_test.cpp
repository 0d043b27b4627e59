// FNC149 MBUS over a serial line (docs/profile-vb.md, "FNC149 MBUS", transports): the RTU
// master's side of each rule, on a pty whose other end plays the slave. A request is address +
// PDU + CRC after t3.5 of silence; one is in flight; a reply with a bad CRC, from another
// station, cut by a pause, or not answering the request is status 6 (Malformed); an exception
// reply is status 6 with its code; silence is status 5 at the deadline (real time); a
// broadcast gets no reply; a late reply to an abandoned request is dropped; a device that goes
// away is status 5 and is opened again, without spinning, once it is back.

#include <gtest/gtest.h>
#include <unistd.h>

#include <array>
#include <asio.hpp>
#include <chrono>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "daemon/master_link.hpp"
#include "modbus/crc.hpp"
#include "modbus/rtu_framer.hpp"
#include "modbus/rtu_master.hpp"
#include "modbus/rtu_frame.hpp"
#include "modbus/rtu_reply.hpp"
#include "support/pty_loop.hpp"

namespace plcemu::modbus {
namespace {

using namespace std::chrono_literals;
using Bytes = std::vector<std::uint8_t>;
using Clock = std::chrono::steady_clock;
using engine::OutboundStatus;
using testing::PluggablePty;

constexpr int kBaud = 9600;      // 8N1: t3.5 = 3.5 × 10 bits / 9600 ≈ 3.65 ms
constexpr int kSlowBaud = 1200;  // 8N1: a character 8.3 ms, t1.5 12.5 ms, t3.5 29 ms

Bytes with_crc(Bytes f) {
    const std::uint16_t crc = crc16(f.data(), f.size());
    f.push_back(static_cast<std::uint8_t>(crc & 0xFF));
    f.push_back(static_cast<std::uint8_t>(crc >> 8));
    return f;
}

// Station 5, FC03, 2 registers from 0.
engine::OutboundRequest read_request(std::uint8_t station = 5, int timeout_ms = 200) {
    engine::OutboundRequest r;
    r.station = station;
    r.function = 3;
    r.address = 0;
    r.quantity = 2;
    r.timeout = std::chrono::milliseconds(timeout_ms);
    return r;
}

const Bytes kReadFrame = with_crc({5, 3, 0, 0, 0, 2});
const Bytes kReadReply = with_crc({5, 3, 4, 0x12, 0x34, 0, 7});

// The master on the slave end of a pty, a link over it, and the master end for the test.
class RtuMasterTest : public ::testing::Test {
protected:
    RtuMasterTest()
        : link_(std::make_unique<daemon::MasterLink>(std::make_unique<RtuMaster>(
              loop_.io, RtuOptions{loop_.pty().link(), kBaud, 'N', 8, 1}))) {}

    // The loop in 1 ms steps: the tests time the line.
    template <class Pred>
    bool run_until(Pred done, std::chrono::milliseconds limit) {
        return loop_.run_until(done, limit, 1ms);
    }
    std::size_t count(const std::string& needle) const { return loop_.count(needle); }
    PluggablePty& pty() { return loop_.pty(); }

    // The master again, at kSlowBaud: tests that time pauses on the line need silences far longer
    // than a loaded machine's scheduling delays.
    void slow_line() {
        link_.reset();
        link_ = std::make_unique<daemon::MasterLink>(
            std::make_unique<RtuMaster>(loop_.io, RtuOptions{pty().link(), kSlowBaud, 'N', 8, 1}));
    }

    // Whatever the master wrote within `limit` (stops at `expected` bytes); stamped when the
    // first byte was read.
    Bytes on_line(std::size_t expected, std::chrono::milliseconds limit = 500ms) {
        Bytes got;
        run_until(
            [&] {
                std::array<std::uint8_t, 300> b{};
                const ssize_t n = ::read(pty().master(), b.data(), b.size());
                if (n > 0) {
                    if (got.empty()) first_byte_at_ = Clock::now();
                    got.insert(got.end(), b.begin(), b.begin() + n);
                }
                return got.size() >= expected;
            },
            limit);
        return got;
    }

    void answer(const Bytes& b) {
        ASSERT_EQ(::write(pty().master(), b.data(), b.size()), static_cast<ssize_t>(b.size()));
    }

    // The completion of the request in flight, waited for up to `limit`.
    std::optional<engine::OutboundCompletion> completion(std::chrono::milliseconds limit = 1s) {
        std::optional<engine::OutboundCompletion> c;
        run_until([&] { return (c = link_->poll()).has_value(); }, limit);
        return c;
    }

    testing::PtyLoop loop_{"rtu-master-test"};
    std::unique_ptr<daemon::MasterLink> link_;
    Clock::time_point first_byte_at_{};
};

TEST_F(RtuMasterTest, RequestIsStationPduAndCrcAndTheReplyGivesItsValues) {
    ASSERT_TRUE(link_->submit(read_request()));
    EXPECT_EQ(on_line(kReadFrame.size()), kReadFrame);
    answer(kReadReply);
    const auto c = completion();
    ASSERT_TRUE(c);
    EXPECT_EQ(c->status, OutboundStatus::Reply);
    EXPECT_EQ(c->values[0], 0x1234);
    EXPECT_EQ(c->values[1], 7);
}

TEST_F(RtuMasterTest, OneRequestInFlight) {
    ASSERT_TRUE(link_->submit(read_request()));
    EXPECT_FALSE(link_->submit(read_request(6)));
    EXPECT_EQ(on_line(kReadFrame.size()), kReadFrame);
    EXPECT_EQ(on_line(1, 50ms), Bytes{}) << "nothing else was sent";
}

// "A reply that is not a valid frame → status 6": bad CRC, another station, a fragment, a pause
// longer than t1.5 inside it; and a valid frame that does not answer the request.
TEST_F(RtuMasterTest, BadCrcIsMalformed) {
    ASSERT_TRUE(link_->submit(read_request()));
    ASSERT_EQ(on_line(kReadFrame.size()), kReadFrame);
    Bytes bad = kReadReply;
    bad.back() ^= 0x01;
    answer(bad);
    const auto c = completion();
    ASSERT_TRUE(c);
    EXPECT_EQ(c->status, OutboundStatus::Malformed);
}

TEST_F(RtuMasterTest, ReplyFromAnotherStationIsMalformed) {
    ASSERT_TRUE(link_->submit(read_request()));
    ASSERT_EQ(on_line(kReadFrame.size()), kReadFrame);
    answer(with_crc({6, 3, 4, 0x12, 0x34, 0, 7}));
    const auto c = completion();
    ASSERT_TRUE(c);
    EXPECT_EQ(c->status, OutboundStatus::Malformed);
}

TEST_F(RtuMasterTest, FragmentIsMalformed) {
    ASSERT_TRUE(link_->submit(read_request()));
    ASSERT_EQ(on_line(kReadFrame.size()), kReadFrame);
    answer({5, 3});
    const auto c = completion();
    ASSERT_TRUE(c);
    EXPECT_EQ(c->status, OutboundStatus::Malformed);
}

TEST_F(RtuMasterTest, PauseInsideTheReplyIsMalformed) {
    slow_line();
    ASSERT_TRUE(link_->submit(read_request(5, 1000)));
    ASSERT_EQ(on_line(kReadFrame.size()), kReadFrame);
    // The master reads the first bytes, then one more 25 ms later: a pause longer than t1.5
    // inside the frame, or, should the loop be late, longer than t3.5, which makes the first
    // bytes a fragment. Either way, no valid frame.
    answer(Bytes(kReadReply.begin(), kReadReply.begin() + 3));
    run_until([] { return false; }, 25ms);
    answer(Bytes(kReadReply.begin() + 3, kReadReply.begin() + 4));
    run_until([] { return false; }, 25ms);
    answer(Bytes(kReadReply.begin() + 4, kReadReply.end()));
    const auto c = completion(2s);
    ASSERT_TRUE(c);
    EXPECT_EQ(c->status, OutboundStatus::Malformed);
}

TEST_F(RtuMasterTest, ReplyThatDoesNotAnswerTheRequestIsMalformed) {
    ASSERT_TRUE(link_->submit(read_request()));
    ASSERT_EQ(on_line(kReadFrame.size()), kReadFrame);
    answer(with_crc({5, 3, 2, 0x12, 0x34}));  // one register for two
    const auto c = completion();
    ASSERT_TRUE(c);
    EXPECT_EQ(c->status, OutboundStatus::Malformed);
}

TEST_F(RtuMasterTest, ExceptionReplyGivesItsCode) {
    ASSERT_TRUE(link_->submit(read_request()));
    ASSERT_EQ(on_line(kReadFrame.size()), kReadFrame);
    answer(with_crc({5, 0x83, 0x02}));
    const auto c = completion();
    ASSERT_TRUE(c);
    EXPECT_EQ(c->status, OutboundStatus::Exception);
    EXPECT_EQ(c->exception, 2);
}

// "Expiry → status 5", in real time from the request.
TEST_F(RtuMasterTest, SilenceTimesOutAtTheDeadline) {
    const auto start = Clock::now();
    ASSERT_TRUE(link_->submit(read_request(5, 120)));
    ASSERT_EQ(on_line(kReadFrame.size()), kReadFrame);
    const auto c = completion(2s);
    const auto took = Clock::now() - start;
    ASSERT_TRUE(c);
    EXPECT_EQ(c->status, OutboundStatus::TimedOut);
    EXPECT_GE(took, 120ms);
    EXPECT_LT(took, 600ms);
}

// "t3.5 of silence before each request", counted from the last byte the line carried: a request
// due while bytes keep coming (one every millisecond or so, less than t3.5 apart) waits for them
// to stop.
TEST_F(RtuMasterTest, RequestWaitsForT35OfSilence) {
    // At 1200 baud t3.5 is 29 ms: a loaded machine writes the noise far more often than that.
    slow_line();
    const auto t35 = RtuTiming::for_line(kSlowBaud, 'N', 8, 1).t35;
    Bytes during;
    Clock::time_point last{};
    auto noise = [&](int ms) {
        for (int i = 0; i < ms; ++i) {
            answer({0xAA});
            last = Clock::now();
            run_until([] { return false; }, 1ms);
            std::array<std::uint8_t, 300> b{};
            const ssize_t n = ::read(pty().master(), b.data(), b.size());
            if (n > 0) during.insert(during.end(), b.begin(), b.begin() + n);
        }
    };
    noise(10);
    ASSERT_TRUE(link_->submit(read_request()));
    noise(20);
    EXPECT_EQ(during, Bytes{}) << "nothing goes out while the line carries bytes";
    ASSERT_EQ(on_line(kReadFrame.size()), kReadFrame);
    EXPECT_GE(first_byte_at_ - last, t35);
}

// A broadcast write (station 0) is done once sent: no station answers one.
TEST_F(RtuMasterTest, BroadcastWriteIsDoneOnceSent) {
    engine::OutboundRequest w;
    w.station = 0;
    w.function = 6;
    w.address = 10;
    w.quantity = 1;
    w.values[0] = 0xBEEF;
    w.timeout = 1000ms;
    const auto start = Clock::now();
    ASSERT_TRUE(link_->submit(w));
    const Bytes expected = with_crc({0, 6, 0, 10, 0xBE, 0xEF});
    EXPECT_EQ(on_line(expected.size()), expected);
    const auto c = completion(2s);
    ASSERT_TRUE(c);
    EXPECT_EQ(c->status, OutboundStatus::Reply);
    EXPECT_LT(Clock::now() - start, 500ms) << "not the time-out";
}

// EN falling: the request is abandoned, and its late reply is not taken for the next one's.
TEST_F(RtuMasterTest, LateReplyToAnAbandonedRequestIsDropped) {
    ASSERT_TRUE(link_->submit(read_request()));
    ASSERT_EQ(on_line(kReadFrame.size()), kReadFrame);
    link_->abandon();
    answer(kReadReply);
    run_until([] { return false; }, 20ms);
    EXPECT_FALSE(link_->poll());
    ASSERT_TRUE(link_->submit(read_request(5, 150)));
    ASSERT_EQ(on_line(kReadFrame.size()), kReadFrame);
    const auto c = completion();
    ASSERT_TRUE(c);
    EXPECT_EQ(c->status, OutboundStatus::TimedOut);
}

// An unplugged device: status 5 for every transfer, logged once, no spinning; once it is back
// (the same path), the next transfer opens it again and is answered.
TEST_F(RtuMasterTest, DeviceThatGoesAwayTimesOutAndIsOpenedAgain) {
    ASSERT_TRUE(link_->submit(read_request()));
    ASSERT_EQ(on_line(kReadFrame.size()), kReadFrame);
    answer(kReadReply);
    ASSERT_TRUE(completion());

    pty().unplug();
    ASSERT_TRUE(run_until([&] { return count("lost") == 1; }, 1000ms)) << loop_.log();
    // A second of transfers, each timed out: one failed open() each, no spinning.
    const double cpu = testing::PtyLoop::cpu_seconds();
    const auto end = Clock::now() + 1s;
    int transfers = 0;
    while (Clock::now() < end) {
        ASSERT_TRUE(link_->submit(read_request(5, 50)));
        std::optional<engine::OutboundCompletion> c;
        loop_.run_until([&] { return (c = link_->poll()).has_value(); }, 1000ms);
        ASSERT_TRUE(c);
        EXPECT_EQ(c->status, OutboundStatus::TimedOut);
        ++transfers;
    }
    EXPECT_GE(transfers, 10);
    EXPECT_LT(testing::PtyLoop::cpu_seconds() - cpu, 0.3);
    EXPECT_EQ(count("lost"), 1u) << loop_.log();
    EXPECT_EQ(count("trying again at every transfer"), 1u) << loop_.log();

    pty().plug();
    ASSERT_TRUE(link_->submit(read_request()));
    ASSERT_EQ(on_line(kReadFrame.size()), kReadFrame);
    answer(kReadReply);
    const auto c = completion();
    ASSERT_TRUE(c);
    EXPECT_EQ(c->status, OutboundStatus::Reply);
    EXPECT_EQ(count(pty().link() + ": reopened"), 1u) << loop_.log();
}

TEST(RtuMasterOpen, MissingDeviceIsAnErrorAtStart) {
    asio::io_context io;
    EXPECT_THROW(
        {
            RtuMaster m(io, RtuOptions{"/nonexistent/tty", kBaud, 'N', 8, 1});
        },
        std::system_error);
}

// At a reload a missing device is taken as one that went away: status 5 meanwhile, and the first
// transfer after it appears opens it.
TEST(RtuMasterOpen, MissingDeviceAtAReloadIsOpenedOnceItAppears) {
    testing::PtyLoop loop("rtu-master-open-test");
    loop.pty().unplug();
    daemon::MasterLink link(std::make_unique<RtuMaster>(
        loop.io, RtuOptions{loop.pty().link(), kBaud, 'N', 8, 1}, RtuMaster::Open::Lazily));
    EXPECT_EQ(loop.count("trying again at every transfer"), 1u) << loop.log();
    std::optional<engine::OutboundCompletion> c;
    auto completed = [&] { return (c = link.poll()).has_value(); };
    ASSERT_TRUE(link.submit(read_request(5, 50)));
    loop.run_until(completed, 1000ms, 1ms);
    ASSERT_TRUE(c);
    EXPECT_EQ(c->status, OutboundStatus::TimedOut);

    loop.pty().plug();
    ASSERT_TRUE(link.submit(read_request(5, 500)));
    Bytes got;
    loop.run_until(
        [&] {
            std::array<std::uint8_t, 64> b{};
            const ssize_t n = ::read(loop.pty().master(), b.data(), b.size());
            if (n > 0) got.insert(got.end(), b.begin(), b.begin() + n);
            return got.size() >= kReadFrame.size();
        },
        500ms, 1ms);
    ASSERT_EQ(got, kReadFrame);
    ASSERT_EQ(::write(loop.pty().master(), kReadReply.data(), kReadReply.size()),
              static_cast<ssize_t>(kReadReply.size()));
    c.reset();
    loop.run_until(completed, 1000ms, 1ms);
    ASSERT_TRUE(c);
    EXPECT_EQ(c->status, OutboundStatus::Reply);
    EXPECT_EQ(loop.count(loop.pty().link() + ": opened"), 1u) << loop.log();
}

// The pure part, as the fuzz harness drives it.
TEST(RtuReply, OnlyAWholeFrameOfTheStationIsAReply) {
    const Bytes f = kReadReply;
    const RtuFrame ok{RtuVerdict::Ok, f};
    const RtuReply r = rtu_reply(ok, 5);
    EXPECT_EQ(r.outcome, MasterOutcome::Reply);
    EXPECT_EQ(Bytes(r.pdu.begin(), r.pdu.end()), (Bytes{3, 4, 0x12, 0x34, 0, 7}));
    EXPECT_EQ(rtu_reply(ok, 6).outcome, MasterOutcome::Garbled);
    EXPECT_EQ(rtu_reply({RtuVerdict::BadCrc, f}, 5).outcome, MasterOutcome::Garbled);
    EXPECT_EQ(rtu_reply({RtuVerdict::Gap, f}, 5).outcome, MasterOutcome::Garbled);
    EXPECT_EQ(rtu_reply({RtuVerdict::TooShort, f}, 5).outcome, MasterOutcome::Garbled);

    std::array<std::uint8_t, RtuFramer::kMaxFrame> out{};
    const Bytes pdu{3, 0, 0, 0, 2};
    const std::size_t n = write_rtu(5, pdu, out);
    EXPECT_EQ(Bytes(out.begin(), out.begin() + static_cast<std::ptrdiff_t>(n)), kReadFrame);
    EXPECT_EQ(write_rtu(5, Bytes(254, 1), out), 0u) << "no frame holds a 254-byte PDU";
}

}  // namespace
}  // namespace plcemu::modbus
