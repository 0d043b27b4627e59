#pragma once
// Modbus RTU framing: turns bytes stamped with their arrival time into frames delimited by the
// t3.5 silence, with the t1.5 rule and the CRC checked. Pure: no clock, no I/O, so the timing
// rules are tested with made-up timestamps and the transport only forwards what it reads.

#include <array>
#include <chrono>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <span>

namespace plcemu::modbus {

/// Character time and the inter-character (t1.5) and inter-frame (t3.5) silences of a line.
struct RtuTiming {
    std::chrono::nanoseconds char_time{0};  ///< one character on the wire
    std::chrono::nanoseconds t15{0};        ///< longest pause allowed inside a frame
    std::chrono::nanoseconds t35{0};        ///< silence that ends a frame

    /// Timing of a line: a character is start + data + parity + stop bits; above 19200 baud the
    /// silences are fixed at 750 µs and 1.75 ms (Modbus over serial line, 2.5.1.1).
    static RtuTiming for_line(int baud, char parity, int data_bits, int stop_bits) noexcept;
};

/// Why a frame was or was not handed on.
enum class RtuVerdict : std::uint8_t {
    Ok,        ///< complete, CRC good
    BadCrc,    ///< CRC mismatch: no answer
    TooShort,  ///< fewer than 4 bytes (address, function, CRC): no answer
    TooLong,   ///< more than 256 bytes: no answer
    Gap,       ///< a pause longer than t1.5 inside the frame: no answer
};

/// A frame that a silence ended.
struct RtuFrame {
    RtuVerdict verdict = RtuVerdict::Ok;  ///< Ok: `bytes` is a request to serve
    std::span<const std::uint8_t> bytes;  ///< address, PDU and CRC; valid until the next call
};

/// Counters of what the framer saw.
struct RtuFramerStats {
    std::uint64_t frames = 0;     ///< frames with a good CRC
    std::uint64_t bad_crc = 0;    ///< frames dropped for their CRC
    std::uint64_t too_short = 0;  ///< fragments under 4 bytes
    std::uint64_t too_long = 0;   ///< frames over 256 bytes
    std::uint64_t gaps = 0;       ///< frames dropped for a t1.5 violation
};

/// Frames a serial byte stream.
///
/// Linux hands over bytes in chunks (UART FIFOs, USB adapters, ptys), stamped when they were
/// read, not when each crossed the wire. The pause before a chunk is therefore taken as the time
/// since the previous chunk minus the time the chunk's own bytes need on the wire: a burst is
/// not a pause, a real pause longer than t1.5 still breaks the frame. A frame ends t3.5 after
/// the last chunk.
class RtuFramer {
public:
    using Clock = std::chrono::steady_clock;
    /// Largest RTU frame: address, 253-byte PDU, CRC.
    static constexpr std::size_t kMaxFrame = 256;

    /// A framer for a line with this timing.
    explicit RtuFramer(RtuTiming timing) noexcept
        : timing_(timing) {}

    /// Bytes read at `now`. When the line was silent for t3.5 before them, the frame in progress
    /// ended first and is returned; the bytes then start a new frame.
    std::optional<RtuFrame> receive(std::span<const std::uint8_t> bytes,
                                    Clock::time_point now) noexcept;
    /// Ends the frame in progress when t3.5 has passed since its last byte at `now`.
    std::optional<RtuFrame> expire(Clock::time_point now) noexcept;
    /// Drops the frame in progress (after a read error).
    void clear() noexcept;
    /// When the frame in progress ends if nothing else arrives; nothing when idle.
    std::optional<Clock::time_point> deadline() const noexcept;

    /// The line's timing.
    const RtuTiming& timing() const noexcept { return timing_; }
    /// Counters since construction.
    const RtuFramerStats& stats() const noexcept { return stats_; }

private:
    RtuFrame finish() noexcept;

    RtuTiming timing_;
    std::array<std::uint8_t, kMaxFrame> buf_{};
    std::array<std::uint8_t, kMaxFrame> done_{};
    std::size_t used_ = 0;      // bytes kept of the frame in progress
    std::size_t received_ = 0;  // bytes received in it (more than kept when too long)
    bool gap_ = false;          // a t1.5 violation happened in it
    Clock::time_point last_{};  // arrival of its last chunk
    RtuFramerStats stats_;
};

}  // namespace plcemu::modbus
