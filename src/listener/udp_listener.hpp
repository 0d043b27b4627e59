#pragma once
// A UDP listener seat: one socket on the Asio event loop, each datagram handed whole to the
// protocol it was given (one frame per datagram, the reply to the sender's address and port,
// as the FATEK Ethernet modules do). No connections: nothing to hold open, nothing to time out.

#include <asio.hpp>
#include <chrono>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "cidr.hpp"
#include "plcemu/listener/protocol.hpp"

namespace plcemu::listener {

/// Listener settings.
struct UdpOptions {
    std::string bind = "0.0.0.0";  ///< address
    std::uint16_t port = 500;      ///< port (0 = any free port)
    std::vector<Cidr> allow;       ///< peers answered (empty = all); others are ignored
    std::string_view protocol{};   ///< the protocol's name, as its clients are listed
    /// A peer silent this long is no longer listed as a client (the console's "heard in the
    /// last minute").
    std::chrono::milliseconds forget_after{std::chrono::minutes(1)};
};

/// The UDP listener.
class UdpListener {
public:
    /// Opens the socket; throws std::system_error naming the endpoint when it cannot be bound.
    /// `protocol` must outlive it.
    UdpListener(asio::io_context& io, StreamProtocol& protocol, UdpOptions options);
    ~UdpListener();
    UdpListener(const UdpListener&) = delete;
    UdpListener& operator=(const UdpListener&) = delete;

    /// The port actually bound.
    std::uint16_t port() const;
    /// The bound endpoint as text.
    std::string endpoint() const;
    /// Takes a new allow list (a reload).
    void set_allow(std::vector<Cidr> allow);
    /// Closes the socket.
    void stop();

    struct State;

private:
    std::shared_ptr<State> state_;
};

}  // namespace plcemu::listener
