#include "rtu_framer.hpp"

#include <algorithm>
#include <cstring>

#include "crc.hpp"

namespace plcemu::modbus {

RtuTiming RtuTiming::for_line(int baud, char parity, int data_bits, int stop_bits) noexcept {
    using std::chrono::nanoseconds;
    const int bits = 1 + data_bits + (parity == 'N' ? 0 : 1) + stop_bits;
    RtuTiming t;
    t.char_time = nanoseconds(std::int64_t{1'000'000'000} * bits / (baud > 0 ? baud : 1));
    if (baud > 19200) {
        t.t15 = std::chrono::microseconds(750);
        t.t35 = std::chrono::microseconds(1750);
    } else {
        t.t15 = t.char_time * 3 / 2;
        t.t35 = t.char_time * 7 / 2;
    }
    return t;
}

std::optional<RtuFrame> RtuFramer::receive(std::span<const std::uint8_t> bytes,
                                           Clock::time_point now) noexcept {
    std::optional<RtuFrame> ended = expire(now);
    if (bytes.empty()) return ended;
    if (received_ > 0) {
        // The pause before this chunk's first byte, had the bytes come one by one off the wire.
        const auto wire = timing_.char_time * static_cast<std::int64_t>(bytes.size());
        if (now - last_ - wire > timing_.t15) gap_ = true;
    }
    const std::size_t take = std::min(bytes.size(), kMaxFrame - used_);
    std::memcpy(buf_.data() + used_, bytes.data(), take);
    used_ += take;
    received_ += bytes.size();
    last_ = now;
    return ended;
}

std::optional<RtuFrame> RtuFramer::expire(Clock::time_point now) noexcept {
    if (received_ == 0 || now - last_ < timing_.t35) return std::nullopt;
    return finish();
}

void RtuFramer::clear() noexcept {
    used_ = 0;
    received_ = 0;
    gap_ = false;
}

std::optional<RtuFramer::Clock::time_point> RtuFramer::deadline() const noexcept {
    if (received_ == 0) return std::nullopt;
    return last_ + timing_.t35;
}

RtuFrame RtuFramer::finish() noexcept {
    RtuFrame f;
    if (received_ > kMaxFrame) {
        f.verdict = RtuVerdict::TooLong;
        ++stats_.too_long;
    } else if (received_ < 4) {
        f.verdict = RtuVerdict::TooShort;
        ++stats_.too_short;
    } else if (gap_) {
        f.verdict = RtuVerdict::Gap;
        ++stats_.gaps;
    } else {
        const std::uint16_t crc = crc16(buf_.data(), used_ - 2);
        const auto sent = static_cast<std::uint16_t>(buf_[used_ - 2] | buf_[used_ - 1] << 8);
        if (crc == sent) {
            ++stats_.frames;
        } else {
            f.verdict = RtuVerdict::BadCrc;
            ++stats_.bad_crc;
        }
    }
    // The caller may read the frame while the next one is being received.
    std::memcpy(done_.data(), buf_.data(), used_);
    f.bytes = {done_.data(), used_};
    used_ = 0;
    received_ = 0;
    gap_ = false;
    return f;
}

}  // namespace plcemu::modbus
