// The UDP listener seat (docs/architecture.md, "How to add a protocol"): each datagram goes whole
// to the protocol and its answer back to the sender; a datagram longer than the protocol's
// largest frame, one the protocol does not answer, and one from a peer off the allow list get
// nothing, and the socket keeps serving.

#include "listener/udp_listener.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <asio.hpp>
#include <cctype>
#include <chrono>
#include <string>

namespace plcemu::listener {
namespace {

using namespace std::chrono_literals;

// Answers a datagram in upper case; one starting with '-' gets no answer.
class Shout final : public StreamProtocol {
public:
    std::size_t max_frame() const noexcept override { return 16; }
    Split split(std::span<const std::uint8_t>) const noexcept override { return {}; }
    std::size_t answer(std::span<const std::uint8_t> frame,
                       std::span<std::uint8_t> out) noexcept override {
        ++answered;
        if (!frame.empty() && frame[0] == '-') return 0;
        if (const Client* c = units_.serving()) traffic.record(*c, Exchange{});
        std::transform(frame.begin(), frame.end(), out.begin(),
                       [](std::uint8_t c) { return static_cast<std::uint8_t>(std::toupper(c)); });
        return frame.size();
    }
    UnitTable& units() noexcept override { return units_; }
    int answered = 0;
    Traffic traffic;  // the peers it lists as clients

private:
    UnitTable units_;
};

class UdpListenerTest : public ::testing::Test {
protected:
    void open(std::vector<Cidr> allow = {},
              std::chrono::milliseconds forget_after = std::chrono::minutes(1)) {
        Seat seat;
        seat.traffic = &shout_.traffic;
        shout_.units().assign({seat});
        UdpOptions o;
        o.bind = "127.0.0.1";
        o.port = 0;
        o.allow = std::move(allow);
        o.forget_after = forget_after;
        listener_ = std::make_unique<UdpListener>(io_, shout_, o);
        client_.open(asio::ip::udp::v4());
    }
    ~UdpListenerTest() override {
        if (listener_) listener_->stop();
    }
    // Sends `text` and runs the loop until an answer came or 300 ms passed; returns the answer.
    std::string ask(const std::string& text) {
        const asio::ip::udp::endpoint to(asio::ip::make_address("127.0.0.1"), listener_->port());
        client_.send_to(asio::buffer(text), to);
        std::string got(64, '\0');
        std::size_t n = 0;
        bool done = false;
        asio::ip::udp::endpoint from;
        client_.async_receive_from(asio::buffer(got), from,
                                   [&](const asio::error_code& ec, std::size_t k) {
                                       if (!ec) n = k;
                                       done = true;
                                   });
        io_.restart();
        io_.run_for(300ms);
        if (!done) {
            client_.cancel();
            io_.restart();
            io_.run_for(50ms);
        }
        got.resize(n);
        return got;
    }

    asio::io_context io_;
    Shout shout_;
    std::unique_ptr<UdpListener> listener_;
    asio::ip::udp::socket client_{io_};
};

TEST_F(UdpListenerTest, EachDatagramIsAnsweredToItsSender) {
    open();
    EXPECT_EQ(ask("abc"), "ABC");
    EXPECT_EQ(ask("x1y2"), "X1Y2");
    EXPECT_EQ(shout_.answered, 2);
    EXPECT_NE(listener_->endpoint().find("127.0.0.1:"), std::string::npos);
}

// The console lists the peers heard in the last minute: one that goes silent leaves the list
// when its time is up, not only when another datagram comes.
TEST_F(UdpListenerTest, APeerSilentTooLongIsNoLongerListedWithoutAnotherDatagram) {
    open({}, 1000ms);
    EXPECT_EQ(ask("abc"), "ABC");  // ask() runs the loop 300 ms
    ASSERT_EQ(shout_.traffic.clients().size(), 1u);
    io_.restart();
    io_.run_for(200ms);
    EXPECT_EQ(shout_.traffic.clients().size(), 1u);  // heard about 500 ms ago: not yet
    io_.restart();
    io_.run_for(800ms);
    EXPECT_TRUE(shout_.traffic.clients().empty());  // about 1.3 s
    EXPECT_EQ(ask("again"), "AGAIN");               // it comes back as a new client
    EXPECT_EQ(shout_.traffic.clients().size(), 1u);
}

TEST_F(UdpListenerTest, UnansweredAndOversizedDatagramsGetNothingAndServingGoesOn) {
    open();
    EXPECT_EQ(ask("-quiet"), "");
    EXPECT_EQ(ask(std::string(17, 'a')), "");  // one byte more than max_frame()
    EXPECT_EQ(shout_.answered, 1);             // the oversized one never reached the protocol
    EXPECT_EQ(ask(std::string(16, 'a')), std::string(16, 'A'));
}

TEST_F(UdpListenerTest, PeersOffTheAllowListAreIgnoredUntilAllowed) {
    const auto other = Cidr::parse("10.0.0.0/8");
    ASSERT_TRUE(other);
    open({*other});
    EXPECT_EQ(ask("abc"), "");
    EXPECT_EQ(shout_.answered, 0);
    const auto local = Cidr::parse("127.0.0.1");
    ASSERT_TRUE(local);
    listener_->set_allow({*local});
    EXPECT_EQ(ask("abc"), "ABC");
}

TEST_F(UdpListenerTest, ABusyPortIsRefusedNamingIt) {
    open();
    UdpOptions o;
    o.bind = "127.0.0.1";
    o.port = listener_->port();
    try {
        UdpListener second(io_, shout_, o);
        FAIL() << "bound a busy port";
    } catch (const std::system_error& e) {
        EXPECT_NE(
            std::string(e.what()).find("cannot listen on udp 127.0.0.1:" + std::to_string(o.port)),
            std::string::npos)
            << e.what();
    }
}

}  // namespace
}  // namespace plcemu::listener
