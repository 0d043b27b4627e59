#pragma once
// Requests a program sends to other devices as a Modbus master (VB manual FNC149 MBUS), handed
// to an outbound link that does the I/O elsewhere: the instruction submits one request and
// polls for its completion at later scans, so a scan never waits on a wire. The daemon
// implements the link on its event loop; tests script it.

#include <array>
#include <chrono>
#include <cstdint>
#include <optional>

namespace plcemu::engine {

/// Most bits or registers one request reads or writes (MBUS: length 1–64).
inline constexpr std::size_t kMaxOutboundItems = 64;

/// One Modbus request to a station.
struct OutboundRequest {
    std::uint8_t station = 0;                ///< slave station (the unit ID over TCP)
    std::uint8_t function = 0;               ///< 1, 2, 3, 4 (reads), 5, 6, 15, 16 (writes)
    std::uint16_t address = 0;               ///< first wire address
    std::uint16_t quantity = 0;              ///< bits or registers, 1–kMaxOutboundItems
    std::chrono::milliseconds timeout{100};  ///< real time the reply may take
    /// The values to write (bits as 0/1); the first `quantity` count.
    std::array<std::uint16_t, kMaxOutboundItems> values{};
};

/// How a request ended.
enum class OutboundStatus : std::uint8_t {
    Reply,      ///< a valid reply; a read's values are in `values`
    Exception,  ///< an exception reply with `exception` as its code
    TimedOut,   ///< no reply within the time-out (or no connection)
    Malformed,  ///< a reply that does not answer the request, or is not a frame at all
};

/// The end of a request.
struct OutboundCompletion {
    OutboundStatus status = OutboundStatus::TimedOut;  ///< how it ended
    std::uint8_t exception = 0;                        ///< exception code (Exception only)
    /// A read's values (bits as 0/1), `quantity` of them (Reply only).
    std::array<std::uint16_t, kMaxOutboundItems> values{};
};

/// Where a master instruction sends its requests. At most one request is in flight.
class OutboundLink {
public:
    virtual ~OutboundLink() = default;
    /// Starts `request`; false (nothing sent) while another one is in flight.
    virtual bool submit(const OutboundRequest& request) noexcept = 0;
    /// The completion of the request in flight, once it has one (nothing is in flight after).
    virtual std::optional<OutboundCompletion> poll() noexcept = 0;
    /// Gives up the request in flight: a reply that comes later is discarded.
    virtual void abandon() noexcept = 0;
};

}  // namespace plcemu::engine
