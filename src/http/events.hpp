#pragma once
// Live updates over Server-Sent Events (`GET /api/v1/plcs/{plc}/events`, `GET /api/v1/events`):
// a response that does not end, carrying an event whenever a watched value changed and the PLCs'
// state once a second. The connection's session asks for them at a fixed period on the loop;
// nothing reads the image from another thread.

#include <chrono>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "http/api.hpp"

namespace plcemu::http {

/// How often a subscription looks for changes.
inline constexpr std::chrono::milliseconds kEventPeriod{50};

/// What one event stream watches, and what it last sent.
class Subscription {
public:
    /// `plc`: the PLC's id, or empty for every PLC's state; `device`/`count`: a span to watch
    /// (empty: none).
    Subscription(std::string plc, std::string device, std::uint32_t count);
    /// The events due now (empty when nothing changed); `units` are the listener's PLCs as they
    /// are now (a reload may have rebuilt them). Sets `ended` when the PLC or device is gone.
    std::string poll(listener::UnitTable& units, bool& ended);

private:
    std::string plc_;
    std::string device_;
    std::uint32_t count_ = 0;
    std::vector<std::uint32_t> last_values_;
    bool sent_values_ = false;
    std::chrono::steady_clock::time_point last_state_{};
    std::chrono::steady_clock::time_point last_sent_{};
};

/// Checks an events request and makes its subscription; a refusal (unknown PLC or device) as
/// the answer to give instead.
std::optional<Subscription> subscribe(const Call& call,
                                      std::string_view plc,
                                      std::optional<Response>& refused);

}  // namespace plcemu::http
