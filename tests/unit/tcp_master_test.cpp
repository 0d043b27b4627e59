// FNC149 MBUS over Modbus TCP (docs/profile-vb.md, "FNC149 MBUS", transports): the TCP master's
// side of each rule, against a scripted slave on a loopback acceptor of the test's own. One
// connection per endpoint, opened by the first transfer and kept; one that cannot be opened, or
// that closes, is status 5 at the deadline and is opened again by the next transfer (never
// before: nothing runs on the loop meanwhile); a reply is taken only with the request's
// transaction ID and unit ID; a bad MBAP header is status 6 and closes the connection; a length
// field that lied costs only its own transfer; a reply may come in pieces or two to a segment; a
// late reply to an abandoned request is dropped, but a flood of frames nobody asked for closes the
// connection; faults in a row hold the reconnect back and are logged once per cause; the
// callback may start a transfer or stop the port. Deadlines are hundreds of ms and only bound
// the wait: the tests assert order and outcomes, and count loop handlers, not wall time.

#include "modbus/tcp_master.hpp"

#include <gtest/gtest.h>

#include <array>
#include <asio.hpp>
#include <chrono>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "support/log_capture.hpp"

namespace plcemu::modbus {
namespace {

using namespace std::chrono_literals;
using asio::ip::tcp;
using Bytes = std::vector<std::uint8_t>;
using Clock = std::chrono::steady_clock;

constexpr std::uint8_t kStation = 5;
const Bytes kReadPdu = {3, 0, 0, 0, 2};            // FC03, 2 registers from 0
const Bytes kReplyPdu = {3, 4, 0x12, 0x34, 0, 7};  // its answer
constexpr auto kDeadline = 300ms;                  // far above a loaded machine's delays
constexpr std::size_t kRequestSize = 7 + 5;        // MBAP + unit + kReadPdu

// An MBAP frame as a slave sends it.
Bytes mbap(std::uint16_t tid,
           std::uint8_t unit,
           const Bytes& pdu,
           std::uint16_t protocol = 0,
           std::optional<std::uint16_t> length = std::nullopt) {
    const auto len = length.value_or(static_cast<std::uint16_t>(pdu.size() + 1));
    Bytes f = {static_cast<std::uint8_t>(tid >> 8),
               static_cast<std::uint8_t>(tid & 0xFF),
               static_cast<std::uint8_t>(protocol >> 8),
               static_cast<std::uint8_t>(protocol & 0xFF),
               static_cast<std::uint8_t>(len >> 8),
               static_cast<std::uint8_t>(len & 0xFF),
               unit};
    f.insert(f.end(), pdu.begin(), pdu.end());
    return f;
}

Bytes operator+(Bytes a, const Bytes& b) {
    a.insert(a.end(), b.begin(), b.end());
    return a;
}

// One connection the slave accepted: what the master sent on it, and whether it closed.
struct Peer {
    explicit Peer(tcp::socket s)
        : socket(std::move(s)) {}
    tcp::socket socket;
    Bytes received;
    bool eof = false;
    std::array<std::uint8_t, 512> chunk{};
};

// What a transfer ended with.
struct Result {
    MasterOutcome outcome;
    Bytes pdu;
    Clock::time_point at;
};

class TcpMasterTest : public ::testing::Test {
protected:
    TcpMasterTest() {
        acceptor_.open(tcp::v4());
        acceptor_.set_option(tcp::acceptor::reuse_address(true));
        acceptor_.bind({asio::ip::make_address("127.0.0.1"), 0});
    }
    ~TcpMasterTest() override {
        master_.reset();
        io_.restart();
        io_.poll();
    }

    // The slave listens (backlog as given) and the master sends every station to it.
    void listen(int backlog = asio::socket_base::max_listen_connections) {
        acceptor_.listen(backlog);
        make_master(acceptor_.local_endpoint());
        accept();
    }
    void make_master(const tcp::endpoint& ep) {
        TcpMasterOptions o;
        o.fallback = ep;
        master_ = std::make_unique<TcpMaster>(io_, o);
    }
    void accept() {
        acceptor_.async_accept([this](const asio::error_code& ec, tcp::socket s) {
            if (ec) return;
            peers_.push_back(std::make_unique<Peer>(std::move(s)));
            read(*peers_.back());
            accept();
        });
    }
    void read(Peer& p) {
        p.socket.async_read_some(
            asio::buffer(p.chunk), [this, &p](const asio::error_code& ec, std::size_t n) {
                if (ec) {
                    p.eof = true;
                    return;
                }
                p.received.insert(p.received.end(), p.chunk.begin(),
                                  p.chunk.begin() + static_cast<std::ptrdiff_t>(n));
                read(p);
            });
    }

    void transact(const Bytes& pdu = kReadPdu, std::chrono::milliseconds deadline = kDeadline) {
        result_.reset();
        sent_at_ = Clock::now();
        master_->transact(kStation, pdu, deadline,
                          [this](MasterOutcome o, std::span<const std::uint8_t> p) {
                              ++calls_;
                              result_ = Result{o, Bytes(p.begin(), p.end()), Clock::now()};
                          });
    }

    // Runs the loop until `done` or `limit`; true when `done`. Counts the handlers run.
    template <class Pred>
    bool run_until(Pred done, std::chrono::milliseconds limit = 3000ms) {
        const auto end = Clock::now() + limit;
        while (!done()) {
            if (Clock::now() > end) return false;
            io_.restart();
            handlers_ += io_.run_for(10ms);
        }
        return true;
    }
    // Runs the loop for `d` whatever happens.
    void run_for(std::chrono::milliseconds d) {
        run_until([] { return false; }, d);
    }
    bool ended() const { return result_.has_value(); }

    // The request the slave's `peer` got last, once all of it is in.
    bool request_in(std::size_t peer, std::size_t count = 1) {
        return run_until([&] {
            return peers_.size() > peer && peers_[peer]->received.size() >= count * kRequestSize;
        });
    }
    std::uint16_t last_tid(std::size_t peer) const {
        const Bytes& r = peers_[peer]->received;
        const std::size_t at = r.size() - kRequestSize;
        return static_cast<std::uint16_t>(r[at] << 8 | r[at + 1]);
    }
    void reply(std::size_t peer, const Bytes& bytes) {
        asio::write(peers_[peer]->socket, asio::buffer(bytes));
    }

    std::size_t count(const std::string& needle) const { return log_.count(needle); }

    // The slave's `peer` answers the request it got last; the transfer ends with that reply.
    void answer(std::size_t peer) {
        reply(peer, mbap(last_tid(peer), kStation, kReplyPdu));
        ASSERT_TRUE(run_until([&] { return ended(); }));
        EXPECT_EQ(result_->outcome, MasterOutcome::Reply);
        EXPECT_EQ(result_->pdu, kReplyPdu);
    }

    // The connection the second request of a test went out on, once it is in.
    std::size_t second_request() {
        EXPECT_TRUE(run_until([&] {
            return !peers_.empty() && peers_.back()->received.size() >= kRequestSize &&
                   (peers_.size() > 1 || peers_[0]->received.size() >= 2 * kRequestSize);
        }));
        return peers_.size() - 1;
    }

    // A completed read on the first connection, to start from a known state.
    void first_transfer() {
        transact();
        ASSERT_TRUE(request_in(0));
        answer(0);
    }

    asio::io_context io_;
    tcp::acceptor acceptor_{io_};
    std::vector<std::unique_ptr<Peer>> peers_;
    std::unique_ptr<MasterTransport> master_;  // the TcpMaster, as the link drives it
    std::optional<Result> result_;
    int calls_ = 0;
    Clock::time_point sent_at_;
    std::size_t handlers_ = 0;
    testing::LogCapture log_{"tcp-master-test", spdlog::level::debug};
};

TEST_F(TcpMasterTest, FirstTransferConnectsSendsMbapAndTakesTheReply) {
    listen();
    transact();
    ASSERT_TRUE(request_in(0));
    // Transaction 1, protocol 0, length = unit + PDU, unit = station, then the PDU.
    EXPECT_EQ(peers_[0]->received, mbap(1, kStation, kReadPdu));
    reply(0, mbap(1, kStation, kReplyPdu));
    ASSERT_TRUE(run_until([&] { return ended(); }));
    EXPECT_EQ(result_->outcome, MasterOutcome::Reply);
    EXPECT_EQ(result_->pdu, kReplyPdu);
    EXPECT_EQ(calls_, 1);
}

// `mbus.tcp.routes` (docs/profile-vb.md, "Transports: `mbus:`"): a routed station goes to its own
// endpoint, every other station to `mbus.tcp`'s; with no fallback an unrouted station is never
// sent and times out.
TEST_F(TcpMasterTest, EachRoutedStationGoesToItsOwnEndpointTheRestToTheFallback) {
    tcp::acceptor routed(io_, {asio::ip::make_address("127.0.0.1"), 0});
    std::optional<tcp::socket> routed_peer;
    routed.async_accept([&](const asio::error_code& ec, tcp::socket s) {
        if (!ec) routed_peer.emplace(std::move(s));
    });
    acceptor_.listen();
    accept();
    TcpMasterOptions o;
    o.fallback = acceptor_.local_endpoint();
    o.routes.emplace_back(std::uint8_t{9}, routed.local_endpoint());
    master_ = std::make_unique<TcpMaster>(io_, o);

    first_transfer();  // station 5: the fallback's
    result_.reset();
    master_->transact(9, kReadPdu, kDeadline,
                      [this](MasterOutcome out, std::span<const std::uint8_t> p) {
                          result_ = Result{out, Bytes(p.begin(), p.end()), Clock::now()};
                      });
    ASSERT_TRUE(run_until([&] { return routed_peer.has_value(); }));
    Bytes got(kRequestSize);
    asio::read(*routed_peer, asio::buffer(got));
    EXPECT_EQ(got, mbap(2, 9, kReadPdu));  // transaction IDs count per master
    asio::write(*routed_peer, asio::buffer(mbap(2, 9, kReplyPdu)));
    ASSERT_TRUE(run_until([&] { return ended(); }));
    EXPECT_EQ(result_->outcome, MasterOutcome::Reply);
    EXPECT_EQ(peers_[0]->received.size(), kRequestSize);  // nothing more went to the fallback

    TcpMasterOptions only_routes;
    only_routes.routes.emplace_back(std::uint8_t{9}, routed.local_endpoint());
    master_ = std::make_unique<TcpMaster>(io_, only_routes);
    transact(kReadPdu, 50ms);  // station 5: no endpoint at all
    ASSERT_TRUE(run_until([&] { return ended(); }));
    EXPECT_EQ(result_->outcome, MasterOutcome::TimedOut);
    EXPECT_GE(result_->at - sent_at_, 50ms);
}

TEST_F(TcpMasterTest, TheConnectionIsKeptForTheNextTransfer) {
    listen();
    first_transfer();
    transact();
    ASSERT_TRUE(request_in(0, 2));
    EXPECT_EQ(last_tid(0), 2);  // a new transaction ID on the same connection
    reply(0, mbap(2, kStation, kReplyPdu));
    ASSERT_TRUE(run_until([&] { return ended(); }));
    EXPECT_EQ(result_->outcome, MasterOutcome::Reply);
    EXPECT_EQ(peers_.size(), 1U);
    EXPECT_EQ(count("connected to"), 1U);
}

TEST_F(TcpMasterTest, ASlaveThatClosesBetweenTransfersIsReconnectedByTheNext) {
    listen();
    first_transfer();
    peers_[0]->socket.close();
    ASSERT_TRUE(run_until([&] { return count("connection lost") == 1; }));
    // Idle after the loss: no reconnect until a transfer needs one, nothing on the loop.
    handlers_ = 0;
    run_for(300ms);
    EXPECT_EQ(peers_.size(), 1U);
    EXPECT_LE(handlers_, 2U);
    transact();
    ASSERT_TRUE(request_in(1));
    answer(1);
}

TEST_F(TcpMasterTest, ASlaveThatClosesDuringATransferCostsItsDeadline) {
    listen();
    transact();
    ASSERT_TRUE(request_in(0));
    peers_[0]->socket.close();
    handlers_ = 0;
    ASSERT_TRUE(run_until([&] { return ended(); }));
    EXPECT_EQ(result_->outcome, MasterOutcome::TimedOut);
    EXPECT_GE(result_->at - sent_at_, kDeadline);  // status 5 once the time-out has passed
    EXPECT_EQ(count("connection lost"), 1U);
    EXPECT_LE(handlers_, 20U);  // the lost connection is not retried while waiting
    EXPECT_EQ(peers_.size(), 1U);
    // The next transfer opens it again.
    transact();
    ASSERT_TRUE(request_in(1));
    answer(1);
}

TEST_F(TcpMasterTest, ARefusedConnectionTimesOutOnceAndIsTriedOncePerTransfer) {
    // A port nobody listens on: bound, never listening.
    make_master(acceptor_.local_endpoint());
    handlers_ = 0;
    transact();
    ASSERT_TRUE(run_until([&] { return ended(); }));
    EXPECT_EQ(result_->outcome, MasterOutcome::TimedOut);
    EXPECT_GE(result_->at - sent_at_, kDeadline);
    EXPECT_EQ(count("cannot connect"), 1U);  // no retry while the deadline runs
    EXPECT_LE(handlers_, 20U);
    handlers_ = 0;
    run_for(300ms);
    EXPECT_EQ(count("cannot connect"), 1U);  // nor after it
    EXPECT_EQ(handlers_, 0U);
    transact();
    ASSERT_TRUE(run_until([&] { return ended(); }));
    EXPECT_EQ(result_->outcome, MasterOutcome::TimedOut);
    EXPECT_EQ(count("cannot connect"), 2U);
    EXPECT_EQ(calls_, 2);
}

TEST_F(TcpMasterTest, ADeadlineWhileConnectingIsStatus5AndTheFrameIsNeverSent) {
    // A listener whose accept queue is full drops the SYN: the master's connect hangs.
    acceptor_.listen(0);
    make_master(acceptor_.local_endpoint());
    std::vector<std::unique_ptr<tcp::socket>> fillers;
    for (int i = 0; i < 4; ++i) {
        fillers.push_back(std::make_unique<tcp::socket>(io_));
        fillers.back()->async_connect(acceptor_.local_endpoint(), [](const asio::error_code&) {});
    }
    run_for(100ms);
    handlers_ = 0;
    transact();
    ASSERT_TRUE(run_until([&] { return ended(); }));
    EXPECT_EQ(result_->outcome, MasterOutcome::TimedOut);
    EXPECT_GE(result_->at - sent_at_, kDeadline);
    EXPECT_EQ(count("connected to"), 0U);
    EXPECT_LE(handlers_, 20U);
    // The queue drains; the master's connect gets through on a SYN retransmit. The abandoned
    // transaction's frame is not sent; the next transfer's is, on that same connect.
    transact(kReadPdu, 5000ms);
    accept();
    ASSERT_TRUE(run_until([&] { return count("connected to") == 1; }, 10000ms));
    std::size_t master_peer = peers_.size();
    ASSERT_TRUE(run_until([&] {
        for (std::size_t i = 0; i < peers_.size(); ++i) {
            if (!peers_[i]->received.empty()) master_peer = i;
        }
        return master_peer < peers_.size() && peers_[master_peer]->received.size() >= kRequestSize;
    }));
    EXPECT_EQ(peers_[master_peer]->received, mbap(2, kStation, kReadPdu));
    reply(master_peer, mbap(2, kStation, kReplyPdu));
    ASSERT_TRUE(run_until([&] { return ended(); }));
    EXPECT_EQ(result_->outcome, MasterOutcome::Reply);
    EXPECT_EQ(calls_, 2);
}

TEST_F(TcpMasterTest, AReplyWithAnotherTransactionIdIsDropped) {
    listen();
    transact();
    ASSERT_TRUE(request_in(0));
    const std::uint16_t tid = last_tid(0);
    // Another ID first, then the right one in the same segment: only the right one is taken.
    reply(0, mbap(static_cast<std::uint16_t>(tid + 1), kStation, {3, 4, 9, 9, 9, 9}) +
                 mbap(tid, kStation, kReplyPdu));
    ASSERT_TRUE(run_until([&] { return ended(); }));
    EXPECT_EQ(result_->outcome, MasterOutcome::Reply);
    EXPECT_EQ(result_->pdu, kReplyPdu);
    // Only another ID: the transfer waits for its deadline.
    transact();
    ASSERT_TRUE(request_in(0, 2));
    reply(0, mbap(static_cast<std::uint16_t>(last_tid(0) + 7), kStation, kReplyPdu));
    ASSERT_TRUE(run_until([&] { return ended(); }));
    EXPECT_EQ(result_->outcome, MasterOutcome::TimedOut);
    EXPECT_FALSE(peers_[0]->eof);  // a well-framed reply keeps the connection
}

TEST_F(TcpMasterTest, AWrongProtocolIdIsGarbledAndClosesTheConnection) {
    listen();
    transact();
    ASSERT_TRUE(request_in(0));
    reply(0, mbap(last_tid(0), kStation, kReplyPdu, 1));
    ASSERT_TRUE(run_until([&] { return ended(); }));
    EXPECT_EQ(result_->outcome, MasterOutcome::Garbled);
    EXPECT_LT(result_->at - sent_at_, kDeadline);  // at once, not at the deadline
    ASSERT_TRUE(run_until([&] { return peers_[0]->eof; }));
    // The next transfer opens a new connection.
    transact();
    ASSERT_TRUE(request_in(1));
    answer(1);
}

TEST_F(TcpMasterTest, AReplyFromAnotherUnitIsGarbled) {
    listen();
    transact();
    ASSERT_TRUE(request_in(0));
    reply(0, mbap(last_tid(0), static_cast<std::uint8_t>(kStation + 1), kReplyPdu));
    ASSERT_TRUE(run_until([&] { return ended(); }));
    EXPECT_EQ(result_->outcome, MasterOutcome::Garbled);
    EXPECT_EQ(calls_, 1);
}

TEST_F(TcpMasterTest, ALengthFieldOutOfRangeIsGarbledAndClosesTheConnection) {
    listen();
    transact();
    ASSERT_TRUE(request_in(0));
    reply(0, mbap(last_tid(0), kStation, kReplyPdu, 0, 300));
    ASSERT_TRUE(run_until([&] { return ended(); }));
    EXPECT_EQ(result_->outcome, MasterOutcome::Garbled);
    ASSERT_TRUE(run_until([&] { return peers_[0]->eof; }));
}

TEST_F(TcpMasterTest, ALengthFieldLongerThanTheReplyCostsOnlyItsOwnTransfer) {
    listen();
    transact();
    ASSERT_TRUE(request_in(0));
    // Says 100 bytes follow, sends 7: the frame never completes.
    reply(0, mbap(last_tid(0), kStation, kReplyPdu, 0, 100));
    ASSERT_TRUE(run_until([&] { return ended(); }));
    EXPECT_EQ(result_->outcome, MasterOutcome::TimedOut);
    // The next transfer gets its own reply, not one swallowed by the lie.
    transact();
    const std::size_t p = second_request();
    answer(p);
    EXPECT_EQ(peers_.size(), 2U);  // on a new connection, in step
    EXPECT_EQ(count("reconnecting"), 1U);
}

TEST_F(TcpMasterTest, ALengthFieldShorterThanTheReplyCostsOnlyItsOwnTransfer) {
    listen();
    transact();
    ASSERT_TRUE(request_in(0));
    // Says 3 bytes (unit + 2 PDU bytes) of a 7-byte body: the master takes a cut PDU, which the
    // reply check refuses; the 4 bytes after it are no frame.
    reply(0, mbap(last_tid(0), kStation, kReplyPdu, 0, 3));
    ASSERT_TRUE(run_until([&] { return ended(); }));
    EXPECT_EQ(result_->outcome, MasterOutcome::Reply);
    EXPECT_EQ(result_->pdu, (Bytes{3, 4}));
    transact();
    const std::size_t p = second_request();
    answer(p);
    EXPECT_EQ(peers_.size(), 2U);
    EXPECT_EQ(count("reconnecting"), 1U);
}

TEST_F(TcpMasterTest, AReplySplitAcrossSegmentsIsReassembled) {
    listen();
    // Thirteen pauses of 20 ms come close to kDeadline on a loaded machine: this test is about
    // reassembly, not the time-out.
    transact(kReadPdu, 3000ms);
    ASSERT_TRUE(request_in(0));
    const Bytes frame = mbap(last_tid(0), kStation, kReplyPdu);
    // One byte at a time, the loop run between them: 3 bytes in (inside the header), then the
    // header whole but the PDU not, then the rest.
    for (std::size_t i = 0; i < frame.size(); ++i) {
        reply(0, {frame[i]});
        run_for(20ms);
        if (i + 1 < frame.size()) {
            EXPECT_FALSE(ended()) << "after " << i + 1 << " bytes";
        }
    }
    ASSERT_TRUE(run_until([&] { return ended(); }));
    EXPECT_EQ(result_->outcome, MasterOutcome::Reply);
    EXPECT_EQ(result_->pdu, kReplyPdu);
}

TEST_F(TcpMasterTest, TwoRepliesInOneSegmentEndOnlyTheirOwnTransfer) {
    listen();
    transact();
    ASSERT_TRUE(request_in(0));
    const std::uint16_t tid = last_tid(0);
    // The reply and a duplicate of it: the second belongs to no transfer once the first ended.
    reply(0, mbap(tid, kStation, kReplyPdu) + mbap(tid, kStation, {3, 4, 1, 1, 1, 1}));
    ASSERT_TRUE(run_until([&] { return ended(); }));
    EXPECT_EQ(result_->pdu, kReplyPdu);
    run_for(100ms);
    EXPECT_EQ(calls_, 1);
    // The next transfer is not ended by the leftover.
    transact();
    ASSERT_TRUE(request_in(0, 2));
    run_for(100ms);
    EXPECT_FALSE(ended());
    answer(0);
    EXPECT_EQ(calls_, 2);
}

TEST_F(TcpMasterTest, ALateReplyToAnAbandonedRequestIsDropped) {
    listen();
    transact();
    ASSERT_TRUE(request_in(0));
    const std::uint16_t old_tid = last_tid(0);
    master_->cancel();
    transact();
    ASSERT_TRUE(request_in(0, 2));
    const std::uint16_t new_tid = last_tid(0);
    EXPECT_NE(new_tid, old_tid);
    // The abandoned request's reply, then the current one's.
    reply(0, mbap(old_tid, kStation, {3, 4, 9, 9, 9, 9}));
    run_for(100ms);
    EXPECT_FALSE(ended());
    reply(0, mbap(new_tid, kStation, kReplyPdu));
    ASSERT_TRUE(run_until([&] { return ended(); }));
    EXPECT_EQ(result_->outcome, MasterOutcome::Reply);
    EXPECT_EQ(result_->pdu, kReplyPdu);
    EXPECT_EQ(calls_, 1);  // the abandoned transfer's callback never runs
}

TEST_F(TcpMasterTest, ATransferStartedFromTheCallbackOfABadHeaderIsSent) {
    listen();
    int outcomes = 0;
    MasterOutcome second = MasterOutcome::Sent;
    master_->transact(kStation, kReadPdu, kDeadline,
                      [&](MasterOutcome o, std::span<const std::uint8_t>) {
                          ++outcomes;
                          EXPECT_EQ(o, MasterOutcome::Garbled);
                          master_->transact(kStation, kReadPdu, kDeadline,
                                            [&](MasterOutcome o2, std::span<const std::uint8_t>) {
                                                ++outcomes;
                                                second = o2;
                                            });
                      });
    ASSERT_TRUE(request_in(0));
    reply(0, mbap(last_tid(0), kStation, kReplyPdu, 1));
    // The bad header closed the first connection; the second transfer goes out on a new one.
    ASSERT_TRUE(request_in(1));
    reply(1, mbap(last_tid(1), kStation, kReplyPdu));
    ASSERT_TRUE(run_until([&] { return outcomes == 2; }));
    EXPECT_EQ(second, MasterOutcome::Reply);
}

TEST_F(TcpMasterTest, StoppingFromTheCallbackWithAnotherFrameBufferedIsSafe) {
    listen();
    bool called = false;
    master_->transact(kStation, kReadPdu, kDeadline,
                      [&](MasterOutcome o, std::span<const std::uint8_t>) {
                          called = true;
                          EXPECT_EQ(o, MasterOutcome::Reply);
                          master_->stop();
                      });
    ASSERT_TRUE(request_in(0));
    const std::uint16_t tid = last_tid(0);
    reply(0, mbap(tid, kStation, kReplyPdu) + mbap(tid, kStation, kReplyPdu));
    ASSERT_TRUE(run_until([&] { return called; }));
    ASSERT_TRUE(run_until([&] { return peers_[0]->eof; }));
}

// A slave sending frames nobody asked for (another transaction's, without end) is closed once
// more than 4 × 260 bytes came since the request: status 6, one line.
TEST_F(TcpMasterTest, ASlaveFloodingFramesNobodyAskedForIsClosed) {
    listen();
    transact();
    ASSERT_TRUE(request_in(0));
    const Bytes stale = mbap(static_cast<std::uint16_t>(last_tid(0) + 1), kStation, kReplyPdu);
    // 1040 bytes are late replies a slow slave may still send: the connection stays.
    Bytes some;
    while (some.size() + stale.size() <= 4 * 260) some = some + stale;
    reply(0, some);
    run_for(100ms);
    EXPECT_FALSE(ended());
    EXPECT_FALSE(peers_[0]->eof);
    reply(0, stale);
    ASSERT_TRUE(run_until([&] { return ended(); }));
    EXPECT_EQ(result_->outcome, MasterOutcome::Garbled);
    EXPECT_LT(result_->at - sent_at_, kDeadline);
    ASSERT_TRUE(run_until([&] { return peers_[0]->eof; }));
    EXPECT_EQ(count("bytes not asked for since the last request; closing"), 1U);
}

// Faults in a row (here bad headers) hold the reconnect back: the first at once, the next after
// 100 ms, then 200 ms; a transfer that ends while it waits is the fault's outcome (status 6),
// without a connection. The fault's lines come once per endpoint and cause.
TEST_F(TcpMasterTest, ReconnectsAfterFaultsInARowBackOffAndAreLoggedOnce) {
    listen();
    const Bytes bad_protocol = {0, 0, 0x12, 0x34, 0, 3, kStation, 3, 0};
    for (std::size_t peer = 0; peer < 2; ++peer) {
        transact();
        ASSERT_TRUE(request_in(peer));
        reply(peer, bad_protocol);
        ASSERT_TRUE(run_until([&] { return ended(); }));
        EXPECT_EQ(result_->outcome, MasterOutcome::Garbled);
    }
    // Two faults: the next connect waits 100 ms, longer than this transfer's 50 ms.
    transact(kReadPdu, 50ms);
    ASSERT_TRUE(run_until([&] { return ended(); }));
    EXPECT_EQ(result_->outcome, MasterOutcome::Garbled);
    run_for(100ms);
    EXPECT_EQ(peers_.size(), 2U);
    // Past the back-off, the next transfer connects; a third fault makes it 200 ms.
    transact();
    ASSERT_TRUE(request_in(2));
    const auto third = Clock::now();
    reply(2, bad_protocol);
    ASSERT_TRUE(run_until([&] { return ended(); }));
    transact(kReadPdu, 1000ms);
    ASSERT_TRUE(run_until([&] { return peers_.size() == 4; }));
    EXPECT_GE(Clock::now() - third, 200ms);
    ASSERT_TRUE(request_in(3));
    answer(3);  // an answer ends the back-off: the next fault reconnects at once
    EXPECT_EQ(count("bad MBAP header; closing"), 1U);
    EXPECT_EQ(count("connected to"), 1U);
}

}  // namespace
}  // namespace plcemu::modbus
