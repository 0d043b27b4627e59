#pragma once
// What the clients of one PLC asked of it, for the console's overview and traffic pages: per
// client its requests, refusals and last request, and the last requests themselves. Protocols
// record into it as they answer (the client being served is the unit table's); views read it.
// It belongs to the PLC's host, so a reload keeps it.

#include <array>
#include <chrono>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include "plcemu/image/area.hpp"

namespace plcemu::listener {

/// What carries a client's requests.
enum class Carrier : std::uint8_t {
    Stream,    ///< a TCP connection
    Datagram,  ///< UDP datagrams from one peer
    Line,      ///< a serial line
};

/// A client of a listener: a TCP connection, a UDP peer, a serial line.
struct Client {
    std::uint64_t id = 0;               ///< unique in the process
    std::string peer;                   ///< "192.0.2.7:50312", "/dev/ttyUSB0"
    std::string_view protocol{};        ///< "modbus-tcp", "fatek"
    Carrier carrier = Carrier::Stream;  ///< what carries its requests
};

/// A client numbered for this process (one loop thread makes them).
Client make_client(std::string peer, std::string_view protocol, Carrier carrier = Carrier::Stream);

/// One request a protocol answered.
struct Exchange {
    std::chrono::system_clock::time_point at{};  ///< when it was answered
    std::uint64_t client = 0;                    ///< Client::id
    std::string_view protocol{};                 ///< "modbus-tcp"
    std::uint8_t unit = 0;                       ///< the unit ID or station it named
    std::uint8_t function = 0;                   ///< Modbus function code, FATEK command code
    std::uint8_t error = 0;     ///< the exception code (Modbus) or error code (FATEK); 0: none
    bool simulator = false;     ///< addressed to the simulator-control unit
    std::uint16_t address = 0;  ///< Modbus: the first address (table as the function says)
    std::uint16_t count = 0;    ///< Modbus: the quantity; 0 when the function has none
    std::uint16_t write_address = 0;  ///< Modbus 17h: the range it writes (the above it reads)
    std::uint16_t write_count = 0;
};

/// One client as the overview shows it.
struct ClientFigures {
    std::uint64_t id = 0;
    std::string peer;
    std::string_view protocol{};
    std::uint64_t requests = 0;  ///< requests it made of this PLC
    std::uint64_t refusals = 0;  ///< of which refused (an exception or error reply)
    std::chrono::system_clock::time_point last{};  ///< its last request
};

/// Requests of one kind answered since start, as metrics count them.
struct RequestCount {
    std::string_view protocol{};  ///< "modbus-tcp", "fatek"
    std::uint8_t function = 0;    ///< function code, command code
    std::uint8_t error = 0;       ///< exception or error code; 0: served
    std::uint64_t count = 0;
};

/// The traffic of one PLC.
class Traffic {
public:
    /// Exchanges kept, the last ones.
    static constexpr std::size_t kKept = 256;

    /// Records an exchange of `client` (a client seen for the first time is added).
    void record(const Client& client, const Exchange& e);
    /// The client left (its connection closed): it is no longer listed.
    void gone(std::uint64_t client) noexcept;
    /// The clients connected, in the order they first asked.
    const std::vector<ClientFigures>& clients() const { return clients_; }
    /// The exchanges kept, oldest first.
    std::vector<Exchange> exchanges() const;
    /// The peer of a client still listed, or "".
    std::string_view peer(std::uint64_t client) const;
    /// Every request recorded since start, counted by protocol, function and error, in the
    /// order each kind was first seen.
    const std::vector<RequestCount>& counts() const { return counts_; }

private:
    void count(const Exchange& e);
    std::uint8_t protocol_number(std::string_view protocol);

    // An exchange as the ring keeps it: 24 bytes instead of 48, its protocol a number in
    // protocols_ (with `simulator` in the top bit), its time to the millisecond (as the list
    // shows it) in 48 bits (to the year 10889), its client's number in 48 (2.8e14 connections),
    // 17h's write range in the bits left. 5,000 PLCs polled keep 1.28 million.
    struct Kept {
        std::uint64_t at_ms : 48;
        std::uint64_t write_address : 16;
        std::uint64_t client : 48;
        std::uint64_t write_count : 16;
        std::uint16_t address;
        std::uint16_t count;
        std::uint8_t protocol;  // index in protocols_ | kSimulator
        std::uint8_t unit;
        std::uint8_t function;
        std::uint8_t error;
    };
    static constexpr std::uint8_t kSimulator = 0x80;
    static_assert(sizeof(Kept) == 24);

    std::vector<ClientFigures> clients_;
    std::size_t last_hit_ = 0;  // the client recorded last: the next request is likely its
    std::vector<RequestCount> counts_;
    std::size_t last_count_ = 0;  // the kind counted last: the next request is likely one
    // The protocols its exchanges were carried by (a PLC speaks a handful at most).
    std::vector<std::string_view> protocols_;
    // Made at the first exchange: most of 5,000 PLCs are never asked anything, and 6 KB of
    // exchanges each would be 30 MB.
    std::unique_ptr<std::array<Kept, kKept>> ring_;
    std::size_t next_ = 0;
    std::size_t size_ = 0;
};

}  // namespace plcemu::listener
