#include "plcemu/listener/comm_faults.hpp"

#include <spdlog/spdlog.h>

#include <algorithm>
#include <mutex>
#include <vector>

#include "modbus/log_limiter.hpp"

namespace plcemu::listener {

namespace {

// A master can switch a fault on and off as fast as it can write (unit 247, the API): the
// lines saying so are the process's, rate-limited as connects are, whichever PLC they are of.
bool may_log() {
    static std::mutex m;
    static modbus::LogLimiter limiter(50, std::chrono::seconds(10));
    const std::lock_guard lock(m);
    const auto now = modbus::LogLimiter::Clock::now();
    limiter.flush_to_log(now, "");
    return limiter.allow(modbus::LogCause::CommFault, now);
}

}  // namespace

CommFaults::CommFaults(std::string label,
                       const image::Naming* naming,
                       std::optional<image::Layout> layout)
    : label_(std::move(label)),
      naming_(naming),
      layout_(std::move(layout)) {}

std::string CommFaults::refusal(const CommFaultSettings& s) const {
    if (std::string why = config::comm_fault_refusal(s); !why.empty()) return why;
    if (s.devices && layout_ && !layout_->contains(*s.devices)) {
        const std::string name = naming_ != nullptr ? naming_->format_range(*s.devices) : "";
        return "from: " + name + " is outside this PLC's devices";
    }
    return {};
}

void CommFaults::set(const CommFaultSettings& s) {
    const CommFaultSettings old = s_;
    s_ = s;
    active_ = s_.any();
    // Counters and generator restart, so the same switch gives the same sequence every time.
    if (s_.drop_probability > 0 || s_.delay_min_ms != s_.delay_max_ms) {
        if (!random_) random_ = std::make_unique<std::mt19937>();
        random_->seed(s_.seed);
    } else {
        random_.reset();
    }
    matched_ = 0;
    served_.clear();

    static const image::Naming kPlain{};
    const image::Naming& naming = naming_ != nullptr ? *naming_ : kPlain;
    const auto before = config::comm_fault_lines(old);
    const auto after = config::comm_fault_lines(s_);
    const std::string scope = config::comm_fault_scope(s_, naming);
    const auto has = [](const std::vector<std::string>& v, const std::string& x) {
        return std::find(v.begin(), v.end(), x) != v.end();
    };
    bool said = false;
    for (const auto& l : before) {
        if (!has(after, l) && may_log()) spdlog::info("{}comm fault off: {}", label_, l);
    }
    for (const auto& l : after) {
        if (has(before, l)) continue;
        if (may_log()) spdlog::info("{}comm fault on: {} ({})", label_, l, scope);
        said = true;
    }
    if (!said && !after.empty() && scope != config::comm_fault_scope(old, naming) && may_log())
        spdlog::info("{}comm faults now apply to {}", label_, scope);
    if (old.stop != s_.stop && on_stop_) on_stop_(s_.stop);
}

bool CommFaults::matches(const Asked& a) const noexcept {
    if (s_.unit != 0 && a.unit != s_.unit) return false;
    if (s_.function != 0 && a.function != s_.function) return false;
    if (!s_.devices) return true;
    return (a.devices && a.devices->overlaps(*s_.devices)) ||
           (a.also && a.also->overlaps(*s_.devices));
}

Verdict CommFaults::judge(const Asked& a) noexcept {
    Verdict v;
    v.fate.by = this;
    if (!active_ || !matches(a)) return v;
    if (s_.offline) {
        ++figures_.silenced;
        v.kind = Verdict::Kind::Silent;
        return v;
    }
    if (s_.exception != 0) {
        ++figures_.refused;
        v.kind = Verdict::Kind::Exception;
        v.code = s_.exception;
    }
    if (s_.drop_every > 0) {
        v.drop = ++matched_ % s_.drop_every == 0;
    } else if (s_.drop_probability > 0) {
        v.drop = std::uniform_real_distribution<double>(0.0, 1.0)(*random_) < s_.drop_probability;
    }
    if (a.carrier == Carrier::Stream && s_.disconnect_after) {
        bool close = *s_.disconnect_after == 0;
        if (close) {
            v.drop = true;  // at once: the request is not answered
        } else {
            // The map's entry goes with the connection (client_gone).
            try {
                close = ++served_[a.client] >= *s_.disconnect_after;
            } catch (const std::bad_alloc&) {
                close = true;  // no room to count: the connection goes now rather than never
            }
        }
        if (close) {
            v.fate.close = s_.reset ? Fate::Close::Reset : Fate::Close::Fin;
            ++figures_.disconnected;
        }
    }
    if (v.drop) {
        ++figures_.dropped;
        return v;  // nothing goes out to be held or spoilt
    }
    if (s_.delay_max_ms > 0) {
        const std::uint32_t ms = s_.delay_min_ms == s_.delay_max_ms
                                     ? s_.delay_max_ms
                                     : std::uniform_int_distribution<std::uint32_t>(
                                           s_.delay_min_ms, s_.delay_max_ms)(*random_);
        v.fate.delay = std::chrono::milliseconds(ms);
        ++figures_.delayed;
    }
    if (a.carrier == Carrier::Line && s_.garble != Garble::None) {
        v.fate.garble = s_.garble;
        ++figures_.garbled;
    }
    return v;
}

}  // namespace plcemu::listener
