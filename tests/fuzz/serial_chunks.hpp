#pragma once
// Shared by the RTU harnesses: fuzz input read as raw chunks of a serial line, through the RTU
// framer as the transports feed it.

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <span>

#include "modbus/rtu_framer.hpp"

namespace plcemu::fuzz {

/// Feeds `in`, records [n][pause][n bytes], to a framer for a line with `timing`: each chunk
/// arrives `pause` half-characters after the previous one went over the wire. `handle` gets
/// what each arrival returns, and what the final t3.5 of silence returns.
template <class Handle>
void feed_chunks(std::span<const std::uint8_t> in,
                 const modbus::RtuTiming& timing,
                 Handle&& handle) {
    modbus::RtuFramer framer(timing);
    modbus::RtuFramer::Clock::time_point now{};
    while (in.size() >= 3) {
        const std::size_t n = std::min<std::size_t>(in[0], in.size() - 2);
        const std::uint8_t pause = in[1];
        const auto chunk = in.subspan(2, n);
        in = in.subspan(2 + n);
        now += timing.char_time * static_cast<std::int64_t>(n) + timing.char_time * pause / 2;
        handle(framer.receive(chunk, now));
    }
    handle(framer.expire(now + timing.t35));
}

}  // namespace plcemu::fuzz
