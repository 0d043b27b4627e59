#pragma once
// A TCP listener seat: the acceptor and its connections on the Asio event loop, carrying the
// protocol it was given (plcemu/listener/protocol.hpp). Many clients, one thread; a client that
// stalls mid-frame only holds its own buffer, a client that does not take its replies is no
// longer read, and connections are served round-robin a few frames at a time.

#include <asio.hpp>
#include <cstdint>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include "cidr.hpp"
#include "plcemu/config/config.hpp"
#include "plcemu/listener/census.hpp"
#include "plcemu/listener/protocol.hpp"

namespace plcemu::listener {

/// Listener settings.
struct TcpOptions {
    /// The config's own value: bind, port (0 = any free port), max_clients (beyond it a
    /// connection is closed at accept), idle_timeout_s, frame_timeout_ms and the allow list.
    config::TcpConfig net;
    std::string section = "modbus.tcp";  ///< the config section, as log lines name its keys
    std::string log_name = "tcp";        ///< what starts its log lines: "tcp", "fatek tcp", "http"
    std::string_view protocol = "";      ///< the protocol's name, as its clients are listed
    /// The PLCs' communication fault `refuse_connections` closes it (the console's listener
    /// stays open whatever the PLCs suffer, so faults can always be switched off).
    bool comm_faults = true;
    /// The process's client room, shared by its listeners (null: none); must outlive them.
    ClientRoom* room = nullptr;
    /// At max_clients, a connection that has sent no request for this long (an event stream
    /// included, whatever it is sent) gives its slot to a new client (docs/operations.md,
    /// "Access control"); shorter in tests.
    std::chrono::milliseconds evict_silent = std::chrono::seconds(30);
};

/// The TCP listener and its connections.
class TcpListener {
public:
    /// Opens the listener; throws std::system_error when the address cannot be bound.
    /// `protocol` must outlive it.
    TcpListener(asio::io_context& io, StreamProtocol& protocol, TcpOptions options);
    ~TcpListener();
    TcpListener(const TcpListener&) = delete;
    TcpListener& operator=(const TcpListener&) = delete;

    /// The port actually bound.
    std::uint16_t port() const;
    /// The listening endpoint as text.
    std::string endpoint() const;
    /// Open connections.
    std::size_t connections() const;
    /// Its connections, as metrics count them.
    ConnectionFigures figures() const;
    /// Takes the limits of `options` that need no new listener (max_clients, timeouts, allow:
    /// a reload); open connections from peers no longer allowed are closed, the others kept.
    void set_limits(const TcpOptions& options);
    /// Closes the listener and every connection.
    void stop();

    struct State;

private:
    std::shared_ptr<State> state_;
};

}  // namespace plcemu::listener
