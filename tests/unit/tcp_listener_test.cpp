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

// Lines ending in '\n', answered in upper case; a line starting with '!' is bad.
class Lines final : public StreamProtocol {
public:
    std::size_t max_frame() const noexcept override { return 64; }
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

class TcpListenerTest : public ::testing::Test {
protected:
    TcpListenerTest() {
        TcpOptions o;
        o.bind = "127.0.0.1";
        o.port = 0;
        listener_ = std::make_unique<TcpListener>(io_, lines_, o);
    }
    ~TcpListenerTest() override { listener_->stop(); }

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
    Lines lines_;
    std::unique_ptr<TcpListener> listener_;
};

TEST_F(TcpListenerTest, CutsFramesWhereTheProtocolSaysAndAnswersPipelinedOnesInOrder) {
    auto s = connect();
    asio::write(s, asio::buffer(std::string("one\ntwo\nthr")));
    EXPECT_EQ(read(s, 8), "ONE\nTWO\n");
    asio::write(s, asio::buffer(std::string("ee\n")));  // the rest of a frame begun before
    EXPECT_EQ(read(s, 6), "THREE\n");
    EXPECT_EQ(lines_.answered, 3);
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
    EXPECT_EQ(lines_.answered, 0);
}

TEST_F(TcpListenerTest, NewLimitsClosePeersTheAllowListNoLongerNames) {
    auto s = connect();
    run_for(50ms);
    ASSERT_EQ(listener_->connections(), 1u);
    TcpOptions o;
    Cidr other;
    ASSERT_TRUE(Cidr::parse("10.0.0.0/8", other));
    o.allow.push_back(other);
    listener_->set_limits(o);
    EXPECT_TRUE(closed(s));
    EXPECT_EQ(listener_->connections(), 0u);
}

}  // namespace
}  // namespace plcemu::listener
