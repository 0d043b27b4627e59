// The TCP listener seat (docs/architecture.md, "How to add a protocol") knows no protocol: it
// carries whatever StreamProtocol it is given. Here a protocol of text lines, which is no
// Modbus at all, proves it: frames are cut where the protocol says, pipelined frames are all
// answered in order, a frame the protocol calls bad closes that connection only, and a reload's
// new limits close a peer the allow list no longer names.

#include "listener/tcp_listener.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <asio.hpp>
#include <cctype>
#include <chrono>
#include <cstdint>
#include <functional>
#include <memory>
#include <string>

#include "support/socket_client.hpp"

namespace plcemu::listener {
namespace {

using namespace std::chrono_literals;

// Lines ending in '\n' of up to `Max` bytes, answered in upper case; a line starting with '!' is
// bad.
template <std::size_t Max>
class LinesOf final : public StreamProtocol {
public:
    std::size_t max_frame() const noexcept override { return Max; }
    Split split(std::span<const std::uint8_t> buffered) const noexcept override {
        if (!buffered.empty() && buffered[0] == '!') return {Cut::Bad, 0, "bad line"};
        const auto end = std::find(buffered.begin(), buffered.end(), std::uint8_t{'\n'});
        if (end == buffered.end()) {
            return buffered.size() >= max_frame() ? Split{Cut::Bad, 0, "line too long"} : Split{};
        }
        return {Cut::Frame, static_cast<std::size_t>(end - buffered.begin()) + 1};
    }
    std::size_t answer(std::span<const std::uint8_t> frame,
                       std::span<std::uint8_t> out) noexcept override {
        ++answered;
        std::transform(frame.begin(), frame.end(), out.begin(),
                       [](std::uint8_t c) { return static_cast<std::uint8_t>(std::toupper(c)); });
        return frame.size();
    }
    UnitTable& units() noexcept override { return units_; }

    int answered = 0;

private:
    UnitTable units_;
};
using Lines = LinesOf<64>;

// A listener on a free port of 127.0.0.1 carrying protocol `P`, and a client's helpers.
template <typename P>
class Seated : public ::testing::Test {
protected:
    Seated() {
        TcpOptions o;
        o.net.bind = "127.0.0.1";
        o.net.port = 0;
        listener_ = std::make_unique<TcpListener>(io_, protocol_, o);
    }
    ~Seated() override { listener_->stop(); }

    asio::ip::tcp::socket connect() {
        asio::ip::tcp::socket s(io_);
        s.connect({asio::ip::make_address("127.0.0.1"), listener_->port()});
        return s;
    }
    // What came back on `s`: `n` bytes, or fewer when it closed or 2 s passed.
    std::string read(asio::ip::tcp::socket& s, std::size_t n) {
        return testing::read_bytes(io_, s, n);
    }
    // True when the listener closed `s` within 2 s.
    bool closed(asio::ip::tcp::socket& s) { return testing::closed(io_, s); }
    void run_for(std::chrono::milliseconds d) {
        io_.restart();
        io_.run_for(d);
    }

    asio::io_context io_;
    P protocol_;
    std::unique_ptr<TcpListener> listener_;
};

using TcpListenerTest = Seated<Lines>;

TEST_F(TcpListenerTest, CutsFramesWhereTheProtocolSaysAndAnswersPipelinedOnesInOrder) {
    auto s = connect();
    asio::write(s, asio::buffer(std::string("one\ntwo\nthr")));
    EXPECT_EQ(read(s, 8), "ONE\nTWO\n");
    asio::write(s, asio::buffer(std::string("ee\n")));  // the rest of a frame begun before
    EXPECT_EQ(read(s, 6), "THREE\n");
    EXPECT_EQ(protocol_.answered, 3);
    EXPECT_EQ(listener_->connections(), 1u);
}

TEST_F(TcpListenerTest, ABadFrameClosesThatConnectionOnlyAfterAnsweringWhatCameBefore) {
    auto a = connect();
    auto b = connect();
    asio::write(a, asio::buffer(std::string("ok\n!no\n")));
    EXPECT_EQ(read(a, 3), "OK\n");
    EXPECT_TRUE(closed(a));
    asio::write(b, asio::buffer(std::string("still\n")));
    EXPECT_EQ(read(b, 6), "STILL\n");
    EXPECT_EQ(listener_->connections(), 1u);
}

TEST_F(TcpListenerTest, AFrameLongerThanTheProtocolAllowsClosesTheConnection) {
    auto s = connect();
    asio::write(s, asio::buffer(std::string(100, 'x')));
    EXPECT_TRUE(closed(s));
    EXPECT_EQ(protocol_.answered, 0);
}

// A connection reads into a small buffer until a read fills it: a frame longer than that, and
// a client that sends many frames at once, are served as with the full buffer from the start.
using GrowingBufferTest = Seated<LinesOf<3000>>;

TEST_F(GrowingBufferTest, FramesLongerThanTheFirstBufferAndManyAtOnceAreServed) {
    auto s = connect();
    const std::string long_line = std::string(2500, 'a') + "\n";
    asio::write(s, asio::buffer(long_line));
    EXPECT_EQ(read(s, long_line.size()), std::string(2500, 'A') + "\n");
    std::string many;
    std::string upper;
    for (int i = 0; i < 1000; ++i) {
        many += "line" + std::to_string(i) + "\n";
        upper += "LINE" + std::to_string(i) + "\n";
    }
    asio::write(s, asio::buffer(many + std::string(2000, 'b')));
    EXPECT_EQ(read(s, upper.size()), upper);
    asio::write(s, asio::buffer(std::string("b\n")));
    EXPECT_EQ(read(s, 2002), std::string(2001, 'B') + "\n");
    EXPECT_EQ(protocol_.answered, 1002);
    EXPECT_EQ(listener_->connections(), 1u);
}

// The descriptors the daemon can give clients are shared by every listener of the process: at
// the room's end, accepting pauses (the peer waits in the backlog, nothing is closed), and it
// resumes once a client leaves.
TEST(TcpListenerRoom, AtTheProcesssClientRoomAcceptsWaitUntilAClientLeaves) {
    asio::io_context io;
    Lines lines;
    Lines other_lines;
    ClientRoom room{2, 0};
    TcpOptions o;
    o.net.bind = "127.0.0.1";
    o.net.port = 0;
    o.room = &room;
    TcpListener one(io, lines, o);
    TcpListener two(io, other_lines, o);
    const auto at = [&](TcpListener& l) {
        asio::ip::tcp::socket s(io);
        s.connect({asio::ip::make_address("127.0.0.1"), l.port()});
        return s;
    };
    auto a = at(one);
    auto b = at(two);
    // Each asks something: a client that has sent nothing gives way to waiting ones (mute_for).
    asio::write(a, asio::buffer(std::string("a\n")));
    asio::write(b, asio::buffer(std::string("b\n")));
    EXPECT_EQ(testing::read_bytes(io, a, 2), "A\n");
    EXPECT_EQ(testing::read_bytes(io, b, 2), "B\n");
    io.restart();
    io.run_for(100ms);
    ASSERT_EQ(room.open, 2);
    // Listener one armed its accept while there was room: the one peer it takes is refused.
    auto c = at(one);
    EXPECT_TRUE(testing::closed(io, c));
    // Then it waits: the kernel completes the handshake, the daemon does not accept.
    auto d = at(one);
    asio::write(d, asio::buffer(std::string("wait\n")));
    io.restart();
    io.run_for(300ms);
    EXPECT_EQ(one.connections() + two.connections(), 2u);
    EXPECT_EQ(lines.answered, 1);  // a's line, not d's
    b.close();                     // a client leaves: d is taken within the back-off (at most 1 s)
    io.restart();
    io.run_for(1500ms);
    EXPECT_EQ(room.open, 2);
    EXPECT_EQ(testing::read_bytes(io, d, 5), "WAIT\n");
    one.stop();
    two.stop();
    io.restart();
    io.run_for(50ms);
    EXPECT_EQ(room.open, 0);
}

TEST_F(TcpListenerTest, NewLimitsClosePeersTheAllowListNoLongerNames) {
    auto s = connect();
    run_for(50ms);
    ASSERT_EQ(listener_->connections(), 1u);
    TcpOptions o;
    const auto other = Cidr::parse("10.0.0.0/8");
    ASSERT_TRUE(other);
    o.net.allow.push_back(*other);
    listener_->set_limits(o);
    EXPECT_TRUE(closed(s));
    EXPECT_EQ(listener_->connections(), 0u);
}

// A protocol with sessions (as HTTP is): each line is answered with its length in as many dots
// (an answer larger than the frame), "tick" starts pushes of "*\n" every 20 ms, "bye" is
// answered and then the connection is closed.
class Dots final : public StreamProtocol {
public:
    class Talk final : public Session {
    public:
        Talk(Outlet& o, Dots& p)
            : outlet_(o),
              protocol_(p) {
            ++protocol_.open_sessions;
        }
        ~Talk() override { --protocol_.open_sessions; }
        Split split(std::span<const std::uint8_t> buffered) const noexcept override {
            const auto end = std::find(buffered.begin(), buffered.end(), std::uint8_t{'\n'});
            if (end == buffered.end()) return {};
            return {Cut::Frame, static_cast<std::size_t>(end - buffered.begin()) + 1};
        }
        bool answer(std::span<const std::uint8_t> frame, std::vector<std::uint8_t>& out) override {
            const std::string line(frame.begin(), frame.end() - 1);
            protocol_.lines.push_back(line);
            if (line == "tick") {
                outlet_.tick_every(20ms);
                return true;
            }
            out.insert(out.end(), 1000 * line.size(), '.');
            out.push_back('\n');
            return line != "bye";
        }
        void tick() override {
            const std::uint8_t push[] = {'*', '\n'};
            outlet_.send(push);
        }

    private:
        Outlet& outlet_;
        Dots& protocol_;
    };

    std::size_t max_frame() const noexcept override { return 64; }
    Split split(std::span<const std::uint8_t>) const noexcept override { return {Cut::Bad, 0, ""}; }
    std::size_t answer(std::span<const std::uint8_t>, std::span<std::uint8_t>) noexcept override {
        return 0;
    }
    std::unique_ptr<Session> open(Outlet& outlet) override {
        return std::make_unique<Talk>(outlet, *this);
    }
    UnitTable& units() noexcept override { return units_; }

    int open_sessions = 0;
    std::vector<std::string> lines;  ///< every line answered, in the order answered

private:
    UnitTable units_;
};

using SessionTest = Seated<Dots>;

// A turn ends once its answers reach 64 kB, not only after 16 frames: sixteen pipelined requests
// with large answers (the console's loop history) held the loop, and every other client, until
// all were answered.
TEST_F(SessionTest, AClientWithLargeAnswersPipelinedTakesTurnsWithTheOthers) {
    auto big = connect();
    auto small = connect();
    run_for(50ms);
    // Sixteen requests of 31,000-byte answers in one read (the first read takes 512 bytes).
    std::string pipelined;
    for (int i = 0; i < 16; ++i)
        pipelined += std::string(30, 'a') + static_cast<char>('A' + i) + "\n";
    ASSERT_EQ(pipelined.size(), 512u);
    asio::write(big, asio::buffer(pipelined));
    asio::write(small, asio::buffer(std::string("b\n")));
    std::string got;
    const auto began = std::chrono::steady_clock::now();
    while (protocol_.lines.size() < 17 && std::chrono::steady_clock::now() - began < 5s) {
        run_for(10ms);
        // Taken as it comes, so that a full socket does not stop the big client's turns.
        asio::error_code ec;
        std::array<char, 1 << 16> b{};
        while (big.available(ec) > 0) big.read_some(asio::buffer(b), ec);
    }
    ASSERT_EQ(protocol_.lines.size(), 17u);
    const auto b = std::find(protocol_.lines.begin(), protocol_.lines.end(), "b");
    ASSERT_NE(b, protocol_.lines.end());
    // Two or three big answers make a turn's 64 kB: "b" is served within the first few.
    EXPECT_LE(b - protocol_.lines.begin(), 4) << "served after the big client's first turns";
    EXPECT_EQ(read(small, 1001), std::string(1000, '.') + "\n");
}

TEST_F(SessionTest, AnswersLargerThanAFramePushesAndACloseTheSessionAskedFor) {
    auto s = connect();
    asio::write(s, asio::buffer(std::string("abc\nde\n")));
    EXPECT_EQ(read(s, 5002), std::string(3000, '.') + "\n" + std::string(2000, '.') + "\n");
    EXPECT_EQ(protocol_.open_sessions, 1);
    asio::write(s, asio::buffer(std::string("tick\n")));
    EXPECT_EQ(read(s, 6), "*\n*\n*\n");  // pushed at the session's pace
    asio::write(s, asio::buffer(std::string("bye\n")));
    const std::string rest = read(s, 1 << 16);
    EXPECT_NE(rest.find(std::string(3000, '.') + "\n"), std::string::npos);
    EXPECT_LT(rest.size(), std::size_t{1} << 16);  // it ended: the connection was closed
    // The session ended with its connection.
    EXPECT_EQ(protocol_.open_sessions, 0);
    EXPECT_EQ(listener_->connections(), 0u);
}

// Streams opened and left running (the console's event streams) held every slot: what a stream
// is sent counted as its client's activity, so none was ever silent enough to give way.
TEST(SessionRoom, AStreamThatSendsNoRequestGivesItsSlotToANewClient) {
    asio::io_context io;
    Dots dots;
    TcpOptions o;
    o.net.bind = "127.0.0.1";
    o.net.port = 0;
    o.net.max_clients = 2;
    o.evict_silent = 300ms;
    TcpListener listener(io, dots, o);
    const auto run_for = [&](std::chrono::milliseconds d) {
        io.restart();
        io.run_for(d);
    };
    const auto connect = [&] {
        asio::ip::tcp::socket s(io);
        s.connect({asio::ip::make_address("127.0.0.1"), listener.port()});
        return s;
    };
    std::array<asio::ip::tcp::socket, 2> streams{connect(), connect()};
    for (auto& s : streams) {
        asio::write(s, asio::buffer(std::string("tick\n")));
        EXPECT_EQ(testing::read_bytes(io, s, 4), "*\n*\n");
    }
    // Longer than evict_silent, every stream pushed to all along.
    run_for(400ms);
    ASSERT_EQ(listener.connections(), 2u);
    auto fresh = connect();
    asio::write(fresh, asio::buffer(std::string("ab\n")));
    EXPECT_EQ(testing::read_bytes(io, fresh, 2001), std::string(2000, '.') + "\n");
    EXPECT_EQ(listener.connections(), 2u);
    // The one silent longest (the first) gave way: what it was pushed, then its end (a reset,
    // as the stream's last pushes were never read), well before read_bytes' 2 s.
    const auto began = std::chrono::steady_clock::now();
    const std::string pushed = testing::read_bytes(io, streams[0], std::size_t{1} << 16);
    EXPECT_LT(pushed.size(), std::size_t{1} << 16);
    EXPECT_LT(std::chrono::steady_clock::now() - began, 1s);
    listener.stop();
}

}  // namespace
}  // namespace plcemu::listener
