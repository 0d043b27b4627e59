#pragma once
// FATEK on a serial line (docs/profile-fbs.md, "FATEK protocol"): frames from STX to ETX as the
// stream cuts them, and a frame begun is abandoned after 1 s without a byte.

#include <array>
#include <chrono>
#include <cstdint>
#include <memory>

#include "frame.hpp"
#include "plcemu/listener/protocol.hpp"

namespace plcemu::fatek {

/// What the serial framing saw.
struct SerialStats {
    std::uint64_t frames = 0;    ///< pieces from STX to ETX
    std::uint64_t answered = 0;  ///< replies sent
    std::uint64_t gaps = 0;      ///< frames abandoned after a silence
    std::uint64_t overflow = 0;  ///< replies dropped: more frames at once than the reply holds
};

/// The FATEK protocol of one serial line.
class FatekSerial final : public listener::SerialProtocol {
public:
    /// A frame begun is abandoned after this long without a byte.
    static constexpr std::chrono::seconds kGap{1};

    /// Serves the PLCs of `setup`.
    explicit FatekSerial(listener::ProtocolSetup setup);

    std::span<const std::uint8_t> receive(std::span<const std::uint8_t> bytes,
                                          Clock::time_point now) noexcept override;
    std::span<const std::uint8_t> expire(Clock::time_point now) noexcept override;
    std::optional<Clock::time_point> deadline() const noexcept override;
    void clear() noexcept override { used_ = 0; }
    listener::UnitTable& units() noexcept override { return units_; }
    std::string summary() const override;

    /// What the framing saw.
    const SerialStats& stats() const noexcept { return stats_; }

private:
    // Cuts and answers every whole frame received, dropping what is no frame.
    void drain() noexcept;
    // Answers one frame, queued after the replies before it (counted as overflow when there is
    // no room left for a reply).
    void answer(std::span<const std::uint8_t> frame) noexcept;
    void abandon_after_gap(Clock::time_point now) noexcept;

    listener::UnitTable units_;
    std::array<std::uint8_t, kMaxFrame> buf_{};
    std::size_t used_ = 0;
    Clock::time_point last_{};
    // Replies to every frame one read completed (a master waits for each, so one is usual).
    std::array<std::uint8_t, 4 * kMaxFrame> reply_{};
    std::size_t reply_size_ = 0;
    // What becomes of those replies (communication faults): the longest hold, the first pause.
    listener::Fate fate_{};
    std::chrono::microseconds gap_{0};  // a garbled reply's pause: ten characters of the line
    SerialStats stats_;
};

/// Makes the protocol for a serial line (listener::ProtocolKind).
std::unique_ptr<listener::SerialProtocol> make_serial(listener::ProtocolSetup setup);

}  // namespace plcemu::fatek
