#pragma once
// A protocol on a listener seat (docs/architecture.md, "How to add a protocol"): a listener
// carries bytes (a TCP connection, a serial line) and hands them to the protocol it names; the
// protocol frames them, reaches the PLCs through the listener's unit table, and frames its
// answers. A listener knows no protocol; a protocol never touches a socket.

#include <chrono>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "plcemu/listener/unit_table.hpp"
#include "plcemu/modbus/line_settings.hpp"

namespace plcemu::listener {

/// What the head of a byte stream holds.
enum class Cut : std::uint8_t {
    Incomplete,  ///< not a whole frame yet: wait for more bytes
    Frame,       ///< a whole frame of `size` bytes
    Skip,        ///< `size` bytes that are no frame (noise before one): dropped, not a request
    Bad,         ///< no frame boundary can be trusted: the connection is closed
};

/// The next frame of a stream.
struct Split {
    Cut cut = Cut::Incomplete;  ///< what was found
    std::size_t size = 0;       ///< bytes of the frame, or to skip (Frame, Skip)
    const char* why = "";       ///< Bad only: "bad MBAP header", for the log
};

/// What a connection offers the session of its client (Session below): bytes sent when the
/// session has something to say outside an answer (a live update), and a period at which it is
/// asked whether it has.
class Outlet {
public:
    virtual ~Outlet() = default;
    /// Queues bytes for the client. False when the client is too far behind in taking what it
    /// was sent: the connection is then closed.
    virtual bool send(std::span<const std::uint8_t> bytes) = 0;
    /// From now on, Session::tick() is called every `period` (zero: no more).
    virtual void tick_every(std::chrono::milliseconds period) = 0;
    /// The client's address, "192.0.2.7:50312".
    virtual const std::string& peer() const = 0;
};

/// One client's conversation, for protocols whose answers may be larger than a frame or come
/// later (HTTP: pages, and live updates over one response). The connection owns it and ends it
/// before its outlet goes away.
class Session {
public:
    virtual ~Session() = default;
    /// Where the next frame of the bytes received and not yet served ends.
    virtual Split split(std::span<const std::uint8_t> buffered) const noexcept = 0;
    /// Answers one whole frame by appending to `out`. False: close the connection once `out`
    /// is sent (the protocol said so, e.g. `Connection: close`).
    virtual bool answer(std::span<const std::uint8_t> frame, std::vector<std::uint8_t>& out) = 0;
    /// Called when the bytes received hold no whole frame yet: appends to `out` what the
    /// protocol says to the client meanwhile (HTTP's "100 Continue" to a request that waits for
    /// it before sending its body). Nothing by default.
    virtual void waiting(std::vector<std::uint8_t>& out) { (void)out; }
    /// Called at the period asked for with Outlet::tick_every.
    virtual void tick() {}
};

/// A protocol carried on a byte stream (one per TCP listener; its connections share it).
class StreamProtocol {
public:
    virtual ~StreamProtocol() = default;
    /// A session for a new client on `outlet`, for a protocol that answers through sessions;
    /// null (the default) for one that answers each frame in place with answer().
    virtual std::unique_ptr<Session> open(Outlet& outlet) {
        (void)outlet;
        return nullptr;
    }
    /// Largest frame, in either direction (at most 1 KiB; a protocol with sessions: the largest
    /// request, at most 64 KiB): a connection's buffers are sized from it, and split() says Bad
    /// rather than Incomplete once that many bytes hold no frame.
    virtual std::size_t max_frame() const noexcept = 0;
    /// Where the next frame of the bytes received and not yet served ends.
    virtual Split split(std::span<const std::uint8_t> buffered) const noexcept = 0;
    /// Answers one whole frame into `out` (max_frame() bytes); returns the answer's size, 0 when
    /// nothing is to be sent.
    virtual std::size_t answer(std::span<const std::uint8_t> frame,
                               std::span<std::uint8_t> out) noexcept = 0;
    /// The PLCs behind the listener.
    virtual UnitTable& units() noexcept = 0;
};

/// A serial line's settings: device, baud, parity, data and stop bits.
using LineSettings = modbus::LineSettings;

/// A protocol carried on a serial line: it frames the bytes as they arrive (by silences or by
/// delimiters) and answers whole frames.
class SerialProtocol {
public:
    using Clock = std::chrono::steady_clock;
    virtual ~SerialProtocol() = default;
    /// Bytes read at `now`. Returns the answer to a frame they completed (or that a silence
    /// before them ended), to be written to the line; empty when there is none. Valid until the
    /// next call.
    virtual std::span<const std::uint8_t> receive(std::span<const std::uint8_t> bytes,
                                                  Clock::time_point now) noexcept = 0;
    /// Called at deadline(): ends a frame a silence completed, and answers it as receive() does.
    virtual std::span<const std::uint8_t> expire(Clock::time_point now) noexcept = 0;
    /// When expire() is due; nothing while no frame is in progress.
    virtual std::optional<Clock::time_point> deadline() const noexcept = 0;
    /// Drops the frame in progress (the line was lost).
    virtual void clear() noexcept = 0;
    /// The PLCs behind the line.
    virtual UnitTable& units() noexcept = 0;
    /// What the framing saw, for the line's last log line ("12 frames with a good CRC; ...").
    virtual std::string summary() const = 0;
};

/// How a listener's protocol is made: from the PLCs it serves, their policy for unknown unit
/// IDs and (serial lines) the line's settings.
struct ProtocolSetup {
    std::vector<Seat> seats;                         ///< the PLCs, in `plcs:` order
    UnknownUnit unknown_unit = UnknownUnit::Refuse;  ///< for IDs none of them has
    LineSettings line;                               ///< serial lines only
    bool read_only = false;  ///< the listener's `read_only`: nothing may be changed through it
};

/// One protocol a listener may name (its config section says which).
struct ProtocolKind {
    std::string_view name;  ///< "modbus-tcp", as logs and docs name it
    /// Makes it for a TCP listener; null for a protocol that is not carried on streams.
    std::unique_ptr<StreamProtocol> (*stream)(ProtocolSetup setup) = nullptr;
    /// Makes it for a UDP listener, which hands answer() one datagram at a time as a whole
    /// frame (split() is not asked); null for a protocol that is not carried on datagrams.
    std::unique_ptr<StreamProtocol> (*datagram)(ProtocolSetup setup) = nullptr;
    /// Makes it for a serial line; null for a protocol that is not carried on serial lines.
    std::unique_ptr<SerialProtocol> (*serial)(ProtocolSetup setup) = nullptr;
};

}  // namespace plcemu::listener
