#include "serial.hpp"

#include <algorithm>
#include <cstring>

#include "serve.hpp"
#include "split.hpp"

namespace plcemu::fatek {

FatekSerial::FatekSerial(listener::ProtocolSetup setup) {
    units_.assign(std::move(setup.seats));
    units_.set_unknown_unit(listener::UnknownUnit::Silent);
    units_.set_read_only(setup.read_only);
    const auto& l = setup.line;
    const int bits = 1 + l.data_bits + (l.parity == 'N' ? 0 : 1) + l.stop_bits;
    gap_ = std::chrono::microseconds(l.baud > 0 ? 10LL * bits * 1000000 / l.baud : 10000);
}

void FatekSerial::abandon_after_gap(Clock::time_point now) noexcept {
    if (used_ == 0 || now - last_ < kGap) return;
    used_ = 0;
    ++stats_.gaps;
}

std::span<const std::uint8_t> FatekSerial::receive(std::span<const std::uint8_t> bytes,
                                                   Clock::time_point now) noexcept {
    abandon_after_gap(now);
    last_ = now;
    reply_size_ = 0;
    fate_ = {};
    while (!bytes.empty()) {
        const std::size_t n = std::min(bytes.size(), buf_.size() - used_);
        std::memcpy(buf_.data() + used_, bytes.data(), n);
        used_ += n;
        bytes = bytes.subspan(n);
        drain();
    }
    units_.fate() = fate_;
    return {reply_.data(), reply_size_};
}

void FatekSerial::drain() noexcept {
    for (;;) {
        const listener::Split s = split_stream({buf_.data(), used_});
        if (s.cut != listener::Cut::Frame && s.cut != listener::Cut::Skip) return;
        // Noise on the line (Skip) is dropped, never answered.
        if (s.cut == listener::Cut::Frame) answer({buf_.data(), s.size});
        std::memmove(buf_.data(), buf_.data() + s.size, used_ - s.size);
        used_ -= s.size;
    }
}

void FatekSerial::answer(std::span<const std::uint8_t> frame) noexcept {
    ++stats_.frames;
    if (reply_.size() - reply_size_ < kMaxFrame) {
        ++stats_.overflow;
        return;
    }
    std::size_t r = serve(units_, frame, std::span(reply_).subspan(reply_size_));
    listener::Fate f = units_.take_fate();
    r = r == 0 ? 0 : listener::cut_or_pause(f, r, gap_);
    fate_.delay = std::max(fate_.delay, f.delay);
    if (fate_.gap_at == 0 && f.gap_at > 0) {
        fate_.gap_at = reply_size_ + f.gap_at;
        fate_.gap = f.gap;
    }
    reply_size_ += r;
    stats_.answered += r > 0 ? 1 : 0;
}

std::span<const std::uint8_t> FatekSerial::expire(Clock::time_point now) noexcept {
    abandon_after_gap(now);
    return {};
}

std::optional<listener::SerialProtocol::Clock::time_point> FatekSerial::deadline() const noexcept {
    if (used_ == 0) return std::nullopt;
    return last_ + kGap;
}

std::string FatekSerial::summary() const {
    return std::to_string(stats_.frames) + " frames, " + std::to_string(stats_.answered) +
           " answered; " + std::to_string(stats_.gaps) + " abandoned after a 1 s silence, " +
           std::to_string(stats_.overflow) + " unanswered (too many at once)";
}

std::unique_ptr<listener::SerialProtocol> make_serial(listener::ProtocolSetup setup) {
    return std::make_unique<FatekSerial>(std::move(setup));
}

}  // namespace plcemu::fatek
