// Modbus RTU framing (docs/profile-fbs.md, "Modbus RTU (serial)"): frames delimited by the t3.5
// silence (fixed 1.75 ms above 19200 baud), t1.5 inside a frame, CRC, frame size limits, and the
// station filter behind the framer (only the station answers; unit 0 is broadcast).

#include <fcntl.h>
#include <gtest/gtest.h>
#include <spdlog/sinks/ostream_sink.h>
#include <spdlog/spdlog.h>
#include <sys/resource.h>
#include <termios.h>
#include <unistd.h>

#include <array>
#include <asio.hpp>
#include <chrono>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <memory>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

#include "modbus/crc.hpp"
#include "modbus/rtu_framer.hpp"
#include "listener/serial_listener.hpp"
#include "modbus_slave/rtu.hpp"
#include "support/profiles.hpp"
#include "plcemu/image/image.hpp"
#include "plcemu/modbus/address_map.hpp"
#include "plcemu/modbus/dispatcher.hpp"
#include "plcemu/modbus/plc_unit.hpp"
#include "support/pluggable_pty.hpp"
#include "support/pty_loop.hpp"
#include "support/wire.hpp"

namespace plcemu::modbus {
namespace {

using testing::PluggablePty;

using namespace std::chrono_literals;
using Bytes = std::vector<std::uint8_t>;
using Clock = RtuFramer::Clock;

Bytes with_crc(Bytes f) {
    const std::uint16_t crc = crc16(f.data(), f.size());
    f.push_back(static_cast<std::uint8_t>(crc & 0xFF));
    f.push_back(static_cast<std::uint8_t>(crc >> 8));
    return f;
}

// Read holding registers 0..9 of station 1: 01 03 0000 000A + CRC.
const Bytes kRequest = with_crc({0x01, 0x03, 0x00, 0x00, 0x00, 0x0A});

Bytes bytes_of(const std::optional<RtuFrame>& f) {
    return f ? Bytes(f->bytes.begin(), f->bytes.end()) : Bytes{};
}

// Feeds `bytes` one per character time from `t`, as a real line with an immediate UART does.
// Returns the time of the last byte.
Clock::time_point feed_bytewise(RtuFramer& fr, const Bytes& bytes, Clock::time_point t) {
    for (std::size_t i = 0; i < bytes.size(); ++i) {
        t += fr.timing().char_time;
        EXPECT_FALSE(fr.receive({&bytes[i], 1}, t)) << "byte " << i << " ended a frame";
    }
    return t;
}

TEST(RtuCrc, KnownVectorAndLowByteFirst) {
    // The Modbus spec's example: 01 03 0000 000A has CRC C5CDh, sent CD C5.
    EXPECT_EQ(crc16(kRequest.data(), 6), 0xCDC5);
    EXPECT_EQ(kRequest[6], 0xC5);
    EXPECT_EQ(kRequest[7], 0xCD);
    const Bytes check = {0x31, 0x32, 0x33, 0x34, 0x35, 0x36, 0x37, 0x38, 0x39};
    EXPECT_EQ(crc16(check.data(), check.size()), 0x4B37);  // CRC-16/MODBUS check value
}

// docs/profile-fbs.md, Modbus RTU (serial): t3.5 is 3.5 character times, fixed 1.75 ms above 19200
// baud; t1.5 likewise (750 µs).
TEST(RtuTiming, CharacterTimesAndFixedSilencesAbove19200) {
    const RtuTiming t9600 = RtuTiming::for_line(9600, 'E', 8, 1);  // 11 bits
    EXPECT_EQ(t9600.char_time, std::chrono::nanoseconds(1'145'833));
    EXPECT_EQ(t9600.t15, t9600.char_time * 3 / 2);
    EXPECT_EQ(t9600.t35, t9600.char_time * 7 / 2);
    EXPECT_EQ(RtuTiming::for_line(9600, 'N', 8, 1).char_time, 1'041'666ns);  // 10 bits
    EXPECT_EQ(RtuTiming::for_line(9600, 'N', 8, 2).char_time, 1'145'833ns);  // 11 bits
    EXPECT_EQ(RtuTiming::for_line(9600, 'E', 7, 1).char_time, 1'041'666ns);  // 10 bits
    const RtuTiming t19200 = RtuTiming::for_line(19200, 'E', 8, 1);
    EXPECT_EQ(t19200.t35, t19200.char_time * 7 / 2);  // 19200 itself still counts characters
    for (int baud : {38400, 57600, 115200, 921600}) {
        const RtuTiming t = RtuTiming::for_line(baud, 'E', 8, 1);
        EXPECT_EQ(t.t35, 1750us) << baud;
        EXPECT_EQ(t.t15, 750us) << baud;
    }
}

// docs/profile-fbs.md, Modbus RTU (serial): a frame ends after a silence of t3.5, not before.
TEST(RtuFramer, FrameEndsAfterT35Silence) {
    RtuFramer fr(RtuTiming::for_line(9600, 'E', 8, 1));
    const auto t0 = Clock::time_point{} + 1s;
    EXPECT_FALSE(fr.deadline());
    EXPECT_FALSE(fr.receive(kRequest, t0));
    ASSERT_TRUE(fr.deadline());
    EXPECT_EQ(*fr.deadline(), t0 + fr.timing().t35);
    EXPECT_FALSE(fr.expire(t0 + fr.timing().t35 - 1ns));
    const auto f = fr.expire(t0 + fr.timing().t35);
    ASSERT_TRUE(f);
    EXPECT_EQ(f->verdict, RtuVerdict::Ok);
    EXPECT_EQ(bytes_of(f), kRequest);
    EXPECT_FALSE(fr.deadline());  // idle again
    EXPECT_FALSE(fr.expire(t0 + 10s));
    EXPECT_EQ(fr.stats().frames, 1u);
}

// A byte-by-byte frame at line speed is one frame; the deadline follows its last byte.
TEST(RtuFramer, BytesAtLineSpeedMakeOneFrame) {
    RtuFramer fr(RtuTiming::for_line(9600, 'E', 8, 1));
    const auto last = feed_bytewise(fr, kRequest, Clock::time_point{} + 1s);
    EXPECT_EQ(*fr.deadline(), last + fr.timing().t35);
    const auto f = fr.expire(last + fr.timing().t35);
    ASSERT_TRUE(f);
    EXPECT_EQ(f->verdict, RtuVerdict::Ok);
    EXPECT_EQ(bytes_of(f), kRequest);
}

// docs/profile-fbs.md, Modbus RTU (serial): a silence of t3.5 before new bytes ends the previous
// frame even when the timer has not been served yet (the event loop was busy); the new bytes start
// the next frame.
TEST(RtuFramer, SilenceBeforeNewBytesEndsThePreviousFrame) {
    RtuFramer fr(RtuTiming::for_line(19200, 'E', 8, 1));
    const auto t0 = Clock::time_point{} + 1s;
    EXPECT_FALSE(fr.receive(kRequest, t0));
    const Bytes second = with_crc({0x01, 0x06, 0x00, 0x01, 0x12, 0x34});
    const auto t1 = t0 + fr.timing().t35 + 1ms;
    const auto first = fr.receive(second, t1);
    ASSERT_TRUE(first);
    EXPECT_EQ(first->verdict, RtuVerdict::Ok);
    EXPECT_EQ(bytes_of(first), kRequest);
    const auto f2 = fr.expire(t1 + fr.timing().t35);
    EXPECT_EQ(bytes_of(f2), second);
}

// Two frames run together without a t3.5 silence are one frame with a bad CRC: no answer.
TEST(RtuFramer, FramesWithoutSilenceBetweenAreOneBadFrame) {
    RtuFramer fr(RtuTiming::for_line(9600, 'E', 8, 1));
    Bytes both = kRequest;
    both.insert(both.end(), kRequest.begin(), kRequest.end());
    const auto t0 = Clock::time_point{} + 1s;
    fr.receive(both, t0);
    const auto f = fr.expire(t0 + fr.timing().t35);
    ASSERT_TRUE(f);
    EXPECT_EQ(f->verdict, RtuVerdict::BadCrc);
    EXPECT_EQ(fr.stats().bad_crc, 1u);
}

// docs/profile-fbs.md, Modbus RTU (serial): a frame with a bad CRC gets no answer (every single-bit
// error is caught).
TEST(RtuFramer, BadCrcIsDropped) {
    for (std::size_t i = 0; i < kRequest.size(); ++i) {
        for (int bit = 0; bit < 8; ++bit) {
            RtuFramer fr(RtuTiming::for_line(115200, 'N', 8, 1));
            Bytes bad = kRequest;
            bad[i] = static_cast<std::uint8_t>(bad[i] ^ (1u << bit));
            fr.receive(bad, Clock::time_point{} + 1s);
            const auto f = fr.expire(Clock::time_point{} + 2s);
            ASSERT_TRUE(f);
            EXPECT_EQ(f->verdict, RtuVerdict::BadCrc) << "byte " << i << " bit " << bit;
        }
    }
}

// t1.5: a pause longer than 1.5 character times (and shorter than t3.5) between two bytes of a
// frame makes the whole frame invalid; a pause up to t1.5 does not.
TEST(RtuFramer, PauseLongerThanT15InsideAFrameDropsIt) {
    const RtuTiming timing = RtuTiming::for_line(9600, 'E', 8, 1);
    const auto c = timing.char_time;
    // Pauses from t3.5 - 1 character on are seen as a frame end: only whole bytes are seen.
    for (const auto pause : {0ns, timing.t15 - 1us, timing.t15 + 10us, timing.t35 - c - 10us}) {
        RtuFramer fr(timing);
        auto t = Clock::time_point{} + 1s;
        const Bytes head(kRequest.begin(), kRequest.begin() + 3);
        const Bytes tail(kRequest.begin() + 3, kRequest.end());
        t = feed_bytewise(fr, head, t);
        // The next byte ends `pause` after the end of the previous one, plus its own wire time.
        t += pause + c;
        EXPECT_FALSE(fr.receive({&tail[0], 1}, t));
        const Bytes rest(tail.begin() + 1, tail.end());
        t = feed_bytewise(fr, rest, t);
        const auto f = fr.expire(t + timing.t35);
        ASSERT_TRUE(f);
        const bool allowed = pause <= timing.t15;
        EXPECT_EQ(f->verdict, allowed ? RtuVerdict::Ok : RtuVerdict::Gap)
            << "pause " << pause.count() << " ns";
    }
}

// A chunk handed over at once (UART FIFO, USB adapter, pty) is not a pause: the bytes in it
// needed their wire time before it could arrive.
TEST(RtuFramer, ChunksAreNotMistakenForPauses) {
    const RtuTiming timing = RtuTiming::for_line(9600, 'E', 8, 1);
    RtuFramer fr(timing);
    const auto t0 = Clock::time_point{} + 1s;
    const Bytes head(kRequest.begin(), kRequest.begin() + 5);
    const Bytes tail(kRequest.begin() + 5, kRequest.end());  // 3 bytes
    EXPECT_FALSE(fr.receive(head, t0));
    // 3 character times later the 3 bytes arrive together: no silence on the wire at all, though
    // the reads are 2 character times further apart than t1.5.
    const auto t1 = t0 + timing.char_time * 3;
    EXPECT_FALSE(fr.receive(tail, t1));
    const auto f = fr.expire(t1 + timing.t35);
    ASSERT_TRUE(f);
    EXPECT_EQ(f->verdict, RtuVerdict::Ok);
    EXPECT_EQ(bytes_of(f), kRequest);
}

// After a dropped frame the framer starts clean: the next good frame is served.
TEST(RtuFramer, RecoversAfterAGap) {
    const RtuTiming timing = RtuTiming::for_line(9600, 'E', 8, 1);
    RtuFramer fr(timing);
    auto t = Clock::time_point{} + 1s;
    fr.receive({kRequest.data(), 4}, t);
    t += timing.t15 + timing.char_time * 5 / 4;  // 1 byte after a pause of t1.5 + 1/4 char
    fr.receive({kRequest.data() + 4, 1}, t);
    auto f = fr.expire(t + timing.t35);
    ASSERT_TRUE(f);
    EXPECT_EQ(f->verdict, RtuVerdict::Gap);
    t += 1s;
    fr.receive(kRequest, t);
    f = fr.expire(t + timing.t35);
    ASSERT_TRUE(f);
    EXPECT_EQ(f->verdict, RtuVerdict::Ok);
    EXPECT_EQ(fr.stats().gaps, 1u);
    EXPECT_EQ(fr.stats().frames, 1u);
}

// After a read error the transport drops the frame in progress: nothing is served from it.
TEST(RtuFramer, ClearDropsTheFrameInProgress) {
    RtuFramer fr(RtuTiming::for_line(9600, 'E', 8, 1));
    const auto t0 = Clock::time_point{} + 1s;
    fr.receive({kRequest.data(), 5}, t0);
    fr.clear();
    EXPECT_FALSE(fr.deadline());
    EXPECT_FALSE(fr.expire(t0 + 1s));
    fr.receive(kRequest, t0 + 2s);
    EXPECT_EQ(bytes_of(fr.expire(t0 + 3s)), kRequest);
}

// Fewer than 4 bytes (address, function code, CRC) is noise; more than 256 is not Modbus.
TEST(RtuFramer, SizeLimits) {
    RtuFramer fr(RtuTiming::for_line(115200, 'E', 8, 1));
    auto t = Clock::time_point{} + 1s;
    const Bytes three = {0x01, 0x03, 0x00};
    fr.receive(three, t);
    EXPECT_EQ(fr.expire(t + 1s)->verdict, RtuVerdict::TooShort);

    t += 2s;
    Bytes big = with_crc(Bytes(254, 0x55));  // 256 bytes: the largest frame
    fr.receive(big, t);
    auto f = fr.expire(t + 1s);
    EXPECT_EQ(f->verdict, RtuVerdict::Ok);
    EXPECT_EQ(f->bytes.size(), 256u);

    t += 2s;
    Bytes huge = with_crc(Bytes(300, 0x55));
    fr.receive({huge.data(), 200}, t);
    fr.receive({huge.data() + 200, huge.size() - 200}, t + 100us);
    f = fr.expire(t + 1s);
    EXPECT_EQ(f->verdict, RtuVerdict::TooLong);
    EXPECT_EQ(fr.stats().too_long, 1u);
    EXPECT_EQ(fr.stats().too_short, 1u);
}

// The station filter behind the framer (docs/profile-fbs.md, Modbus RTU (serial)): framed bytes
// reach the dispatcher, which answers the station, stays silent for other stations and for
// broadcasts, and applies broadcast writes.
class RtuStation : public ::testing::Test {
protected:
    image::Image img_{testing::fbs_layout()};
    PlcUnit unit_{img_, testing::fbs().map(), {}};
    std::uint8_t station_ = 7;
    Dispatcher disp_{Identity{"FATEK", "FBs-24MC", "9.9.9"}};
    plcemu::testing::Wire wire_{disp_, unit_, station_};
    RtuFramer framer_{RtuTiming::for_line(9600, 'E', 8, 1)};
    Clock::time_point t_ = Clock::time_point{} + 1s;

    // Frames `frame` through the framer, then serves it as the RTU transport does; returns the
    // reply PDU, empty for silence.
    Bytes send(const Bytes& frame) {
        t_ += 1s;
        EXPECT_FALSE(framer_.receive(frame, t_));
        const auto f = framer_.expire(t_ + framer_.timing().t35);
        if (!f || f->verdict != RtuVerdict::Ok) return {};
        // Wire adds its own address and CRC: hand it the framed PDU.
        const Bytes pdu(f->bytes.begin() + 1, f->bytes.end() - 2);
        return wire_.rtu(f->bytes[0], pdu);
    }
};

TEST_F(RtuStation, OnlyTheStationAnswers) {
    img_.write_word({image::Area::R, 3, false}, 0x1234);
    const Bytes read = {0x03, 0x00, 0x03, 0x00, 0x01};
    auto frame = [&](std::uint8_t unit) {
        Bytes f{unit};
        f.insert(f.end(), read.begin(), read.end());
        return with_crc(f);
    };
    EXPECT_EQ(plcemu::testing::reply_words(send(frame(7))), (std::vector<std::uint16_t>{0x1234}));
    EXPECT_TRUE(send(frame(1)).empty());    // another station
    EXPECT_TRUE(send(frame(255)).empty());  // 255 is a TCP convention only
    EXPECT_TRUE(send(frame(0)).empty());    // broadcast read: ignored
    Bytes corrupt = frame(7);
    corrupt[3] ^= 0x01;
    EXPECT_TRUE(send(corrupt).empty());  // bad CRC: silence
}

TEST_F(RtuStation, BroadcastWritesApplyWithoutAnswer) {
    EXPECT_TRUE(send(with_crc({0x00, 0x06, 0x00, 0x05, 0xAB, 0xCD})).empty());
    EXPECT_EQ(img_.word(image::Area::R, 5), 0xABCD);
}

// The serial listener carrying Modbus RTU on a pty that goes away and comes back: reopened by path,
// with back-off, logged once each way, and no reopen after stop().
class RtuReopen : public RtuStation {
protected:
    template <class Pred>
    bool run_until(Pred done, std::chrono::milliseconds limit) {
        return loop_.run_until(done, limit);
    }
    std::size_t count(const std::string& needle) const { return loop_.count(needle); }
    static double cpu_seconds() { return testing::PtyLoop::cpu_seconds(); }
    PluggablePty& pty() { return loop_.pty(); }
    // Modbus RTU for the station, on a 115200 8N1 line.
    modbus_slave::ModbusRtu protocol_{{{{"", &station_, &disp_, &unit_, 0, nullptr}},
                                       listener::UnknownUnit::Silent,
                                       {"", 115200, 'N', 8, 1}}};

    // Sends a read of R4055 on the master end until the station's reply comes back (a request
    // written before the device is reopened is flushed by the open) or `limit` has passed.
    bool answered(std::chrono::milliseconds limit = 2000ms) {
        const Bytes req = with_crc({0x07, 0x03, 0x0F, 0xD7, 0x00, 0x01});
        const auto end = std::chrono::steady_clock::now() + limit;
        while (std::chrono::steady_clock::now() < end) {
            std::array<std::uint8_t, 64> b{};
            while (::read(pty().master(), b.data(), b.size()) > 0) {
            }
            if (::write(pty().master(), req.data(), req.size()) !=
                static_cast<ssize_t>(req.size())) {
                return false;
            }
            Bytes got;
            run_until(
                [&] {
                    const ssize_t n = ::read(pty().master(), b.data(), b.size());
                    if (n > 0) got.insert(got.end(), b.begin(), b.begin() + n);
                    return got.size() >= 7;
                },
                200ms);
            if (got.size() == 7 && got[0] == 0x07 && got[1] == 0x03) return true;
        }
        return false;
    }

    testing::PtyLoop loop_{"rtu-test"};
    asio::io_context& io_ = loop_.io;
};

TEST_F(RtuReopen, DeviceThatComesBackIsReopenedWithoutSpinning) {
    listener::SerialListener server(io_, protocol_, {pty().link(), 115200, 'N', 8, 1}, "rtu",
                                    "modbus-rtu");
    ASSERT_TRUE(answered());

    pty().unplug();
    ASSERT_TRUE(run_until([&] { return count("lost") == 1; }, 2000ms)) << loop_.log();
    // Gone for 2 s: a few silent attempts (0.1 s doubling), no busy loop.
    const double cpu = cpu_seconds();
    run_until([] { return false; }, 2000ms);
    EXPECT_LT(cpu_seconds() - cpu, 0.3);
    EXPECT_EQ(count("lost"), 1u) << loop_.log();
    EXPECT_EQ(count("reopened"), 0u) << loop_.log();

    pty().plug();
    EXPECT_TRUE(answered(6000ms)) << loop_.log();  // the next attempt is at most 5 s away
    EXPECT_EQ(count("lost"), 1u) << loop_.log();
    EXPECT_EQ(count("reopened"), 1u) << loop_.log();
    EXPECT_EQ(count(pty().link() + ": reopened"), 1u) << loop_.log();
}

TEST_F(RtuReopen, StopDuringTheBackOffLeavesNothingToRun) {
    listener::SerialListener server(io_, protocol_, {pty().link(), 115200, 'N', 8, 1}, "rtu",
                                    "modbus-rtu");
    pty().unplug();
    ASSERT_TRUE(run_until([&] { return count("lost") == 1; }, 2000ms)) << loop_.log();
    server.stop();
    // With the back-off timer cancelled the loop runs out of work at once.
    io_.restart();
    const auto start = std::chrono::steady_clock::now();
    io_.run_for(3s);
    EXPECT_LT(std::chrono::steady_clock::now() - start, 500ms);
    EXPECT_EQ(count("reopened"), 0u) << loop_.log();
}

}  // namespace
}  // namespace plcemu::modbus
